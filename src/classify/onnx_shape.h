/* src/classify/onnx_shape.h (internal): read a model's input shape straight from the ONNX file.
 * OpenCV 4.6 does not report the input shape of a loaded network, so we walk the protobuf:
 * ModelProto.graph -> GraphProto.input (minus initializers) -> type.tensor_type.shape.dim. */
#ifndef VF_ONNX_SHAPE_H
#define VF_ONNX_SHAPE_H

#include <stddef.h>

/* Dimensions of the first real graph input of the serialized model in data[size] (at most max,
 * -1 for a symbolic dimension such as a batch "N"). Returns their number, or 0 when the data is
 * not a readable ONNX model or has no shaped input. */
int vf_onnx_input_dims(const unsigned char *data, size_t size, long long *dims, int max);

#endif
