/* vf/view_loss.h: what a classifier makes of a radiance field seen from given viewpoints.
 *
 * The attack's objective in one object: render a batch of ViewFool viewpoints (or camera
 * poses) of a field with the classifier camera (the S x S crop a classifier sees of a training
 * photo, vf_field_classifier_camera), normalize, classify the batch, and score it against a
 * true label set. Everything stays in memory: no files in the loop. The loss of a view is
 * the cross-entropy of the label set, from the logits z in double precision
 * (vf_label_set_cross_entropy),
 *
 *     L(v) = -log( sum over y in the set of p_y(R(v)) ) = logsumexp(z) - logsumexp(z_set),
 *
 * so confidently correct views still differ in loss (and give a search gradient) and fooled
 * views do not saturate.
 *
 * and the view fools the classifier when its top-1 class is outside the set. Rendering and
 * classification use every core; buffers are allocated once, for VF_VIEW_LOSS_CHUNK views,
 * so memory stays flat whatever the batch size.
 *
 * Threads: one vf_view_loss is used by one thread at a time (it owns scratch buffers and
 * borrows a classifier, which is not re-entrant). Memory: the field and classifier are
 * borrowed and must outlive it; free it with vf_view_loss_free. */
#ifndef VF_VIEW_LOSS_H
#define VF_VIEW_LOSS_H

#include <stddef.h> /* vf/field.h uses size_t without including it */

#include "vf/camera.h"
#include "vf/classifier.h"
#include "vf/error.h"
#include "vf/field.h"
#include "vf/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_VIEW_LOSS_CHUNK 16   /* views rendered and classified together */

typedef struct vf_view_prediction {
    int top_class;    /* top-1 ImageNet class */
    float top_prob;   /* its probability */
    float label_prob; /* total probability of the label set, exp(-loss) (0 before labels are set) */
    int correct;      /* top_class is in the label set (an untrusted view: 1, see below) */
    double gap_deg;   /* the view's gap to the photos (vf/view_coverage.h); NAN: no trust set */
    int untrusted;    /* the gap is over the trust limit: not rendered, never fooled */
} vf_view_prediction;

/* Time spent so far, for reports and benchmarks. */
typedef struct vf_view_loss_stats {
    long views;             /* views rendered and classified */
    double render_seconds;  /* wall time in the renderer */
    double classify_seconds; /* wall time normalizing and in the network */
} vf_view_loss_stats;

typedef struct vf_view_loss vf_view_loss;

/* Borrow field and classifier; the camera is the classifier camera for the model's input size. */
vf_status vf_view_loss_create(const vf_field *field, vf_classifier *cls, vf_view_loss **out);
void vf_view_loss_free(vf_view_loss *vl);

/* Set the true label set (1..VF_MAX_LABELS ImageNet classes). */
vf_status vf_view_loss_set_labels(vf_view_loss *vl, const int *labels, int count);

vf_camera vf_view_loss_camera(const vf_view_loss *vl);
vf_view_loss_stats vf_view_loss_get_stats(const vf_view_loss *vl);

/* Classify n views: viewpoints (n x 6: psi, theta, phi degrees, dx, dy, dz) or camera poses
 * (n row-major 4x4 camera-to-world matrices, OpenGL axes). out gets n predictions; losses
 * (may be NULL) n losses. */
vf_status vf_view_loss_classify(vf_view_loss *vl, const double *views, int n,
                                vf_view_prediction *out, double *losses);
vf_status vf_view_loss_classify_poses(vf_view_loss *vl, const double *c2w, int n,
                                      vf_view_prediction *out);

/* Classify n images that are already the model's S x S RGB input (photos or renders of the
 * object itself, seen with the classifier camera), scored against the label set like renders
 * of the field. VF_EINPUT when an image has another size. */
vf_status vf_view_loss_classify_images(vf_view_loss *vl, const vf_image *images, int n,
                                       vf_view_prediction *out);

/* Viewpoints the field can vouch for (vf/view_coverage.h): from now on a viewpoint of
 * vf_view_loss_classify whose gap to the `count` photo cameras (count x 16, borrowed, must
 * outlive vl) exceeds limit_deg is not rendered: its prediction is "untrusted", correct (never
 * counted as fooled), top_class -1, and its loss is -(gap - limit) / limit, below every
 * rendered view's (cross-entropies are >= 0) and lower the farther out, so the search is
 * pushed back towards the photos instead of finding its viewpoints in fog. limit_deg <= 0
 * switches the limit off (every view rendered, its gap still given). Camera poses
 * (vf_view_loss_classify_poses) are always rendered. */
void vf_view_loss_set_trust(vf_view_loss *vl, const double *photos, int count, double limit_deg);

/* The attack's loss callback (vf/viewfool.h, vf_attack_loss_fn); ctx is a vf_view_loss with
 * its labels set. */
vf_status vf_view_loss_fn(const double *views, int n, double *losses, int *fooled, void *ctx);

/* Render one viewpoint with the classifier camera into out (allocated as vf_field_render). */
vf_status vf_view_loss_render(const vf_view_loss *vl, const double view[6], vf_image *out);

/* The class most views predict (ties: the smaller index) and how many predict it. */
int vf_majority_class(const vf_view_prediction *pred, int n, int *votes);

#ifdef __cplusplus
}
#endif
#endif
