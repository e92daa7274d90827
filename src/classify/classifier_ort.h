/* src/classify/classifier_ort.h (internal): the ONNX Runtime engine behind vf/classifier.h.
 *
 * Debian has no ONNX Runtime package and the npm one (onnxruntime-node, which scripts/setup.sh
 * installs) has no C headers, so the model runs in a worker process of the project's own
 * (ort_worker.js, built into the library) that loads it once and exchanges batches with us over
 * a Unix socket: one copy of the floats each way, no files. The worker is Node.js running
 * ONNX Runtime's CPU provider on every core.
 *
 * Where things are found: node is $VF_NODE, else `node` on PATH; the package is
 * $VF_ONNXRUNTIME_DIR/node_modules/onnxruntime-node, else the same under
 * <user data>/onnxruntime (vf_user_data_dir). Not re-entrant: one thread at a time. */
#ifndef VF_CLASSIFIER_ORT_H
#define VF_CLASSIFIER_ORT_H

#include <stddef.h>

#include "vf/error.h"

typedef struct vf_ort vf_ort;

/* Are node and the package installed? VF_OK, else VF_EINTERNAL saying what is missing and how
 * to install it. Cheap (two file lookups). */
vf_status vf_ort_available(void);

/* Start a worker and load the model at path. VF_EINPUT "model PATH is not an ONNX classifier:
 * <ONNX Runtime's reason>" when the runtime refuses it (its reason names the op that failed). */
vf_status vf_ort_load(const char *path, vf_ort **out);

/* The runtime's version ("1.30.0"). */
const char *vf_ort_version(const vf_ort *ort);

/* The square input side the graph states, or 0 when its spatial dimensions are symbolic. */
int vf_ort_input_size(const vf_ort *ort);

/* Run n NCHW inputs of size x size (transposed here when the model takes NHWC) and write
 * n * classes outputs; VF_EINPUT when the model's output has another number of values. */
vf_status vf_ort_forward(vf_ort *ort, const float *nchw, int n, int size, float *out,
                         int classes);

/* Stop the worker; NULL is fine. */
void vf_ort_free(vf_ort *ort);

#endif
