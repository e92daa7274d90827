/* One step's batch of viewpoints: evaluate, summarize, remember the best, append the record
 * (viewfool_internal.h). Shared by the NES and PEPG steps. */
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"

vf_status vf__evaluate_batch(vf_attack_loss_fn loss_fn, void *ctx, const double *views, int n,
                             double *losses, int *fooled)
{
    memset(fooled, 0, (size_t)n * sizeof *fooled);
    vf_status status = loss_fn(views, n, losses, fooled, ctx);
    if (status != VF_OK)
        return status;
    for (int j = 0; j < n; j++)
        if (!isfinite(losses[j]))
            return vf_fail(VF_EINTERNAL,
                           "the loss at viewpoint %d of %d is %g: the classifier "
                           "or renderer returned no usable value",
                           j, n, losses[j]);
    return VF_OK;
}

vf_status vf__history_push(vf_attack_state *st, const vf_attack_record *rec)
{
    if (st->step >= st->history_cap) {
        int cap = st->history_cap ? 2 * st->history_cap : 128;
        vf_attack_record *grown = realloc(st->history, (size_t)cap * sizeof *grown);
        if (!grown)
            return vf_fail(VF_EINTERNAL, "out of memory for the attack history");
        st->history = grown;
        st->history_cap = cap;
    }
    st->history[st->step] = *rec;
    return VF_OK;
}

void vf__note_best(vf_attack_state *st, const double *views, const double *losses, int n)
{
    int best = 0;
    for (int j = 1; j < n; j++)
        if (losses[j] > losses[best])
            best = j;
    st->last_best_loss = losses[best];
    memcpy(st->last_best_view, views + best * VF_VIEW_DIM, sizeof st->last_best_view);
    if (losses[best] > st->best_loss) {
        st->best_loss = losses[best];
        memcpy(st->best_view, st->last_best_view, sizeof st->best_view);
    }
}

void vf__batch_stats(const double *losses, const int *fooled, int n, vf_attack_record *rec)
{
    double sum = 0.0, top = -INFINITY;
    int n_fooled = 0;
    for (int j = 0; j < n; j++) {
        sum += losses[j];
        top = losses[j] > top ? losses[j] : top;
        n_fooled += fooled[j] != 0;
    }
    rec->mean_loss = sum / n;
    rec->max_loss = top;
    rec->fooled_rate = (double)n_fooled / n;
}
