/* Frame selection: blurry-frame rejection against the local median, then the sharpest
 * distinct frame of each stretch. See vf/frame_select.h for the rules. */
#include "vf/frame_select.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "vf/stats.h"

#define LIVE_RING (int)(sizeof(((vf_live_counter *)0)->recent) / sizeof(double))

void vf_select_defaults(vf_select_params *params)
{
    params->max_frames = 100;
    params->blur_ratio = 0.4;
    params->blur_window = 7;
    params->duplicate_threshold = 1.5;
    params->unordered = 0;
}

const char *vf_frame_verdict_name(vf_frame_verdict verdict)
{
    switch (verdict) {
    case VF_FRAME_CHOSEN:
        return "chosen";
    case VF_FRAME_BLURRY:
        return "blurry";
    case VF_FRAME_DUPLICATE:
        return "duplicate";
    default:
        return "unused";
    }
}

static vf_status check_params(const vf_select_params *p)
{
    if (p->max_frames < 1)
        return vf_fail(VF_EINPUT, "the number of frames to keep must be at least 1");
    if (!(p->blur_ratio >= 0 && p->blur_ratio < 1))
        return vf_fail(VF_EINPUT, "the blur ratio must be in [0, 1), not %g", p->blur_ratio);
    if (p->blur_window < 1 || 2 * p->blur_window + 1 > LIVE_RING)
        return vf_fail(VF_EINPUT, "the blur window must be 1..%d frames", (LIVE_RING - 1) / 2);
    if (!(p->duplicate_threshold >= 0))
        return vf_fail(VF_EINPUT, "the duplicate threshold must be >= 0");
    return VF_OK;
}

static vf_status alloc_selection(int count, vf_selection *s)
{
    size_t n = (size_t)count + 1; /* never a zero-size allocation */
    memset(s, 0, sizeof *s);
    s->count = count;
    s->verdict = calloc(n, sizeof *s->verdict);
    s->local_median = calloc(n, sizeof *s->local_median);
    s->duplicate_of = calloc(n, sizeof *s->duplicate_of);
    s->difference = calloc(n, sizeof *s->difference);
    s->chosen = calloc(n, sizeof *s->chosen);
    if (!s->verdict || !s->local_median || !s->duplicate_of || !s->difference || !s->chosen) {
        vf_selection_free(s);
        return vf_fail(VF_EINTERNAL, "out of memory selecting among %d frames", count);
    }
    for (int i = 0; i < count; i++)
        s->duplicate_of[i] = -1;
    return VF_OK;
}

/* Step 1: mark frames much blurrier than the median of their neighbourhood. */
static void reject_blurry(const vf_frame_score *scores, const vf_select_params *p, vf_selection *s)
{
    double window[LIVE_RING];
    double *all = p->unordered && s->count > 0 ? malloc((size_t)s->count * sizeof *all) : NULL;
    if (all) {
        for (int i = 0; i < s->count; i++)
            all[i] = scores[i].sharpness;
        double global = vf_median(all, s->count);
        for (int i = 0; i < s->count; i++) {
            s->local_median[i] = global;
            if (scores[i].sharpness < p->blur_ratio * global)
                s->verdict[i] = VF_FRAME_BLURRY;
        }
        free(all);
        return;
    }
    for (int i = 0; i < s->count; i++) {
        int lo = i - p->blur_window < 0 ? 0 : i - p->blur_window;
        int hi = i + p->blur_window >= s->count ? s->count - 1 : i + p->blur_window;
        for (int j = lo; j <= hi; j++)
            window[j - lo] = scores[j].sharpness;
        s->local_median[i] = vf_median(window, hi - lo + 1);
        if (scores[i].sharpness < p->blur_ratio * s->local_median[i])
            s->verdict[i] = VF_FRAME_BLURRY;
    }
}

typedef struct ranked {
    double sharpness;
    int index;
} ranked;

static int sharper_first(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->sharpness != y->sharpness)
        return x->sharpness < y->sharpness ? 1 : -1;
    return x->index - y->index; /* ties: the earlier frame */
}

/* Step 2 for one stretch [lo, hi): choose its sharpest usable frame that does not repeat the
 * previously chosen one (*last, updated). `order` is scratch space for hi - lo entries. */
static void choose_in_stretch(const vf_frame_score *scores, int lo, int hi,
                              const vf_select_params *p, ranked *order, int *last,
                              vf_selection *s)
{
    int n = 0;
    for (int i = lo; i < hi; i++)
        if (s->verdict[i] == VF_FRAME_UNUSED)
            order[n++] = (ranked){scores[i].sharpness, i};
    qsort(order, (size_t)n, sizeof *order, sharper_first);
    for (int k = 0; k < n; k++) {
        int i = order[k].index;
        if (*last >= 0) {
            double d = vf_thumb_difference(&scores[i], &scores[*last]);
            if (d < p->duplicate_threshold) {
                s->verdict[i] = VF_FRAME_DUPLICATE;
                s->duplicate_of[i] = *last;
                s->difference[i] = d;
                continue;
            }
        }
        s->verdict[i] = VF_FRAME_CHOSEN;
        s->chosen[s->chosen_count++] = i;
        *last = i;
        return;
    }
}

vf_status vf_select_frames(const vf_frame_score *scores, int count, const vf_select_params *params,
                           vf_selection *out)
{
    vf_status status = check_params(params);
    if (status == VF_OK && count < 0)
        status = vf_fail(VF_EINPUT, "negative frame count");
    if (status != VF_OK)
        return status;
    vf_selection s;
    if ((status = alloc_selection(count, &s)) != VF_OK)
        return status;
    ranked *order = malloc(sizeof *order * ((size_t)count + 1));
    if (!order) {
        vf_selection_free(&s);
        return vf_fail(VF_EINTERNAL, "out of memory selecting among %d frames", count);
    }
    reject_blurry(scores, params, &s);
    int stretches = count < params->max_frames ? count : params->max_frames;
    int last = -1;
    for (int k = 0; k < stretches; k++) {
        int lo = (int)((int64_t)k * count / stretches);
        int hi = (int)((int64_t)(k + 1) * count / stretches);
        choose_in_stretch(scores, lo, hi, params, order, &last, &s);
    }
    free(order);
    *out = s;
    return VF_OK;
}

void vf_selection_free(vf_selection *s)
{
    if (!s)
        return;
    free(s->verdict);
    free(s->local_median);
    free(s->duplicate_of);
    free(s->difference);
    free(s->chosen);
    memset(s, 0, sizeof *s);
}

int vf_live_counter_add(vf_live_counter *c, const vf_frame_score *score,
                        const vf_select_params *params)
{
    int window = 2 * params->blur_window + 1;
    if (window > LIVE_RING)
        window = LIVE_RING;
    c->recent[c->seen % LIVE_RING] = score->sharpness;
    c->seen++;
    int n = c->seen < window ? c->seen : window;
    double values[LIVE_RING];
    for (int k = 0; k < n; k++)
        values[k] = c->recent[(c->seen - 1 - k) % LIVE_RING];
    int usable = score->sharpness >= params->blur_ratio * vf_median(values, n) &&
                 (c->usable == 0 ||
                  vf_thumb_difference(score, &c->last) >= params->duplicate_threshold);
    if (usable) {
        c->last = *score;
        c->usable++;
    }
    return usable;
}
