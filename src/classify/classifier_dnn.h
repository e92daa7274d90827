/* src/classify/classifier_dnn.h (internal): the OpenCV dnn calls behind vf/classifier.h.
 * An ONNX network loaded once and run on CPU batches; not re-entrant (one thread at a time). */
#ifndef VF_CLASSIFIER_DNN_H
#define VF_CLASSIFIER_DNN_H

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_dnn vf_dnn;

/* Read an ONNX file; VF_EINPUT "model PATH is not an ONNX classifier: ..." when OpenCV cannot. */
vf_status vf_dnn_load(const char *path, vf_dnn **out);

/* Run n NCHW inputs of size x size; write n * classes outputs. Fails (VF_EINPUT) when the
 * model's output does not have `classes` values per input. */
vf_status vf_dnn_forward(vf_dnn *net, const float *nchw, int n, int size, float *out, int classes);

void vf_dnn_free(vf_dnn *net);

/* OpenCV's version ("4.6.0"). */
const char *vf_dnn_version(void);

#ifdef __cplusplus
}
#endif
#endif
