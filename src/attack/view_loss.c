/* Render -> normalize -> classify -> score, a chunk of views at a time (vf/view_loss.h). */
#include "vf/view_loss.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vf/log.h"
#include "vf/pose.h"
#include "vf/view_coverage.h"

struct vf_view_loss {
    const vf_field *field;
    vf_classifier *cls;
    vf_camera camera;
    int size; /* model input side S */
    int labels[VF_MAX_LABELS], label_count;
    vf_image images[VF_VIEW_LOSS_CHUNK]; /* render targets, reused */
    float *batch;                         /* chunk x 3 x S x S network input */
    float *logits;                        /* chunk x 1000 */
    double losses[VF_VIEW_LOSS_CHUNK];    /* the chunk's label-set cross-entropies */
    vf_view_loss_stats stats;
    const double *photos; /* the trust's photo cameras (NULL: every view is rendered) */
    int photo_count;
    double trust_limit;
};

vf_status vf_view_loss_create(const vf_field *field, vf_classifier *cls, vf_view_loss **out)
{
    vf_view_loss *vl = calloc(1, sizeof *vl);
    if (!vl)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vl->field = field;
    vl->cls = cls;
    vl->size = vf_classifier_input_size(cls);
    vl->camera = vf_field_classifier_camera(field, vl->size);
    size_t plane = (size_t)vl->size * (size_t)vl->size;
    vl->batch = malloc(VF_VIEW_LOSS_CHUNK * 3 * plane * sizeof(float));
    vl->logits = malloc(VF_VIEW_LOSS_CHUNK * VF_NUM_CLASSES * sizeof(float));
    if (!vl->batch || !vl->logits) {
        vf_view_loss_free(vl);
        return vf_fail(VF_EINTERNAL, "out of memory for the classifier batch");
    }
    *out = vl;
    return VF_OK;
}

void vf_view_loss_free(vf_view_loss *vl)
{
    if (!vl)
        return;
    for (int i = 0; i < VF_VIEW_LOSS_CHUNK; i++)
        vf_image_free(&vl->images[i]);
    free(vl->batch);
    free(vl->logits);
    free(vl);
}

vf_status vf_view_loss_set_labels(vf_view_loss *vl, const int *labels, int count)
{
    if (count < 1 || count > VF_MAX_LABELS)
        return vf_fail(VF_EINPUT, "a label set holds 1 to %d classes, not %d", VF_MAX_LABELS,
                       count);
    for (int i = 0; i < count; i++)
        if (labels[i] < 0 || labels[i] >= VF_NUM_CLASSES)
            return vf_fail(VF_EINPUT, "label %d is not an ImageNet class (0..999)", labels[i]);
    memcpy(vl->labels, labels, (size_t)count * sizeof *labels);
    vl->label_count = count;
    return VF_OK;
}

vf_camera vf_view_loss_camera(const vf_view_loss *vl) { return vl->camera; }

vf_view_loss_stats vf_view_loss_get_stats(const vf_view_loss *vl) { return vl->stats; }

/* One view's prediction from its logits (overwritten with probabilities) and its loss. */
static void predict(const vf_view_loss *vl, float *logits, vf_view_prediction *out, double *loss)
{
    *loss = vf_label_set_cross_entropy(logits, vl->labels, vl->label_count);
    vf_softmax(logits, VF_NUM_CLASSES);
    int top;
    vf_topk(logits, 1, &top, &out->top_prob);
    out->top_class = top;
    out->correct = vf_label_set_contains(vl->labels, vl->label_count, top);
    out->label_prob = (float)exp(-*loss);
    out->gap_deg = NAN;
    out->untrusted = 0;
}

/* Classify n (<= chunk) images of the model's input size. */
static vf_status classify_chunk(vf_view_loss *vl, const vf_image *images, int n,
                                vf_view_prediction *out)
{
    double t0 = vf_now();
    size_t stride = 3 * (size_t)vl->size * (size_t)vl->size;
    vf_first_error error = {0}; /* a worker's failure was dropped here before */
#pragma omp parallel for
    for (int i = 0; i < n; i++)
        vf_first_error_keep(&error,
                            vf_classifier_normalize(&images[i], vl->batch + (size_t)i * stride));
    vf_status status = vf_first_error_raise(&error);
    if (status == VF_OK)
        status = vf_classifier_logits(vl->cls, vl->batch, n, vl->logits);
    if (status != VF_OK)
        return status;
    for (int i = 0; i < n; i++)
        predict(vl, vl->logits + (size_t)i * VF_NUM_CLASSES, &out[i], &vl->losses[i]);
    vl->stats.classify_seconds += vf_now() - t0;
    vl->stats.views += n;
    return VF_OK;
}

vf_status vf_view_loss_classify_images(vf_view_loss *vl, const vf_image *images, int n,
                                       vf_view_prediction *out)
{
    for (int i = 0; i < n; i++)
        if (images[i].width != vl->size || images[i].height != vl->size || images[i].channels != 3)
            return vf_fail(VF_EINPUT, "image %d is %dx%d with %d channels, not the model's "
                                      "%dx%d RGB",
                           i, images[i].width, images[i].height, images[i].channels, vl->size,
                           vl->size);
    for (int first = 0; first < n; first += VF_VIEW_LOSS_CHUNK) {
        int m = n - first < VF_VIEW_LOSS_CHUNK ? n - first : VF_VIEW_LOSS_CHUNK;
        vf_status status = classify_chunk(vl, images + first, m, out + first);
        if (status != VF_OK)
            return status;
    }
    return VF_OK;
}

void vf_view_loss_set_trust(vf_view_loss *vl, const double *photos, int count, double limit_deg)
{
    int on = photos && count > 0;
    vl->photos = on ? photos : NULL;
    vl->photo_count = on ? count : 0;
    vl->trust_limit = limit_deg > 0 ? limit_deg : INFINITY;
}

/* An untrusted view's prediction and loss (vf_view_loss_set_trust). */
static double untrusted(const vf_view_loss *vl, double gap, vf_view_prediction *out)
{
    *out = (vf_view_prediction){.top_class = -1, .correct = 1, .gap_deg = gap, .untrusted = 1};
    return -(gap - vl->trust_limit) / vl->trust_limit;
}

vf_status vf_view_loss_classify(vf_view_loss *vl, const double *views, int n,
                                vf_view_prediction *out, double *losses)
{
    for (int first = 0; first < n;) {
        /* the next chunk of views to render; untrusted ones are answered on the way */
        vf_viewpoint vp[VF_VIEW_LOSS_CHUNK];
        int index[VF_VIEW_LOSS_CHUNK], m = 0;
        double gap[VF_VIEW_LOSS_CHUNK];
        for (; first < n && m < VF_VIEW_LOSS_CHUNK; first++) {
            const double *v = views + 6 * (size_t)first;
            double g = vl->photos ? vf_view_trust_of(vl->photos, vl->photo_count, v).gap_deg : NAN;
            if (g > vl->trust_limit) { /* NAN (no photos) compares false */
                double loss = untrusted(vl, g, &out[first]);
                if (losses)
                    losses[first] = loss;
                continue;
            }
            gap[m] = g;
            index[m] = first;
            vp[m++] = vf_viewpoint_from_array(v);
        }
        if (!m)
            continue;
        vf_view_prediction pred[VF_VIEW_LOSS_CHUNK];
        double t0 = vf_now();
        vf_status status = vf_field_render_viewpoints(vl->field, &vl->camera, vp, m, vl->images);
        vl->stats.render_seconds += vf_now() - t0;
        if (status == VF_OK)
            status = classify_chunk(vl, vl->images, m, pred);
        if (status != VF_OK)
            return status;
        for (int i = 0; i < m; i++) {
            out[index[i]] = pred[i];
            out[index[i]].gap_deg = gap[i];
            if (losses)
                losses[index[i]] = vl->losses[i];
        }
    }
    return VF_OK;
}

vf_status vf_view_loss_classify_poses(vf_view_loss *vl, const double *c2w, int n,
                                      vf_view_prediction *out)
{
    for (int first = 0; first < n; first += VF_VIEW_LOSS_CHUNK) {
        int m = n - first < VF_VIEW_LOSS_CHUNK ? n - first : VF_VIEW_LOSS_CHUNK;
        double t0 = vf_now();
        vf_status status =
            vf_field_render_batch(vl->field, &vl->camera, c2w + 16 * (size_t)first, m, vl->images);
        vl->stats.render_seconds += vf_now() - t0;
        if (status == VF_OK)
            status = classify_chunk(vl, vl->images, m, out + first);
        if (status != VF_OK)
            return status;
    }
    return VF_OK;
}

vf_status vf_view_loss_fn(const double *views, int n, double *losses, int *fooled, void *ctx)
{
    vf_view_loss *vl = ctx;
    if (vl->label_count < 1)
        return vf_fail(VF_EINTERNAL, "the attack loss has no label set");
    vf_view_prediction *pred = malloc((size_t)n * sizeof *pred);
    if (!pred)
        return vf_fail(VF_EINTERNAL, "out of memory for %d predictions", n);
    vf_status status = vf_view_loss_classify(vl, views, n, pred, losses);
    for (int i = 0; status == VF_OK && fooled && i < n; i++)
        fooled[i] = !pred[i].correct;
    free(pred);
    return status;
}

vf_status vf_view_loss_render(const vf_view_loss *vl, const double view[6], vf_image *out)
{
    vf_viewpoint vp = vf_viewpoint_from_array(view);
    return vf_field_render_viewpoints(vl->field, &vl->camera, &vp, 1, out);
}

int vf_majority_class(const vf_view_prediction *pred, int n, int *votes)
{
    int count[VF_NUM_CLASSES] = {0}, best = 0;
    for (int i = 0; i < n; i++)
        count[pred[i].top_class]++;
    for (int c = 1; c < VF_NUM_CLASSES; c++)
        if (count[c] > count[best])
            best = c;
    if (votes)
        *votes = count[best];
    return best;
}
