/* The ONNX input-shape walker (src/classify/onnx_shape.c) on protobuf messages built here: the
 * first input that is not an initializer, symbolic dimensions, malformed data, and a model that
 * lists thousands of weights among its inputs (once quadratic: 31 s for a 3.7 MB model). */
#include <stdlib.h>
#include <string.h>

#include "../src/classify/onnx_shape.h"
#include "check.h"
#include "vf/log.h"

typedef struct buf {
    unsigned char *data;
    size_t size, cap;
} buf;

static void put_bytes(buf *b, const void *p, size_t n)
{
    if (b->size + n > b->cap) {
        b->cap = 2 * (b->size + n) + 64;
        b->data = realloc(b->data, b->cap);
    }
    memcpy(b->data + b->size, p, n);
    b->size += n;
}

static void put_varint(buf *b, unsigned long long x)
{
    do {
        unsigned char byte = (unsigned char)(x & 0x7f);
        x >>= 7;
        if (x)
            byte |= 0x80;
        put_bytes(b, &byte, 1);
    } while (x);
}

/* A length-delimited field holding msg (which is freed). */
static void put_message(buf *b, int number, buf *msg)
{
    put_varint(b, (unsigned long long)number << 3 | 2);
    put_varint(b, msg->size);
    put_bytes(b, msg->data, msg->size);
    free(msg->data);
    *msg = (buf){0};
}

static void put_string(buf *b, int number, const char *s)
{
    put_varint(b, (unsigned long long)number << 3 | 2);
    put_varint(b, strlen(s));
    put_bytes(b, s, strlen(s));
}

/* ValueInfoProto{name, type.tensor_type.shape.dim[].dim_value} (dim < 0: symbolic). */
static void put_input(buf *graph, const char *name, const long long *dims, int n)
{
    buf shape = {0}, tensor = {0}, type = {0}, info = {0};
    for (int i = 0; i < n; i++) {
        buf dim = {0};
        if (dims[i] >= 0) {
            put_varint(&dim, 1 << 3 | 0);
            put_varint(&dim, (unsigned long long)dims[i]);
        } else {
            put_string(&dim, 2, "N"); /* dim_param */
        }
        put_message(&shape, 1, &dim);
    }
    put_message(&tensor, 2, &shape);
    put_message(&type, 1, &tensor);
    put_string(&info, 1, name);
    put_message(&info, 2, &type);
    put_message(graph, 11, &info);
}

static void put_initializer(buf *graph, const char *name)
{
    buf tensor = {0};
    put_string(&tensor, 8, name);
    put_message(graph, 5, &tensor);
}

static buf model_of(buf *graph)
{
    buf model = {0};
    put_varint(&model, 1 << 3 | 0); /* ir_version */
    put_varint(&model, 7);
    put_message(&model, 7, graph);
    return model;
}

static void test_small(void)
{
    buf graph = {0};
    const long long weight[2] = {32, 3}, image[4] = {-1, 3, 160, 160};
    put_initializer(&graph, "w1");
    put_input(&graph, "w1", weight, 2); /* a weight listed as an input: skipped */
    put_input(&graph, "input", image, 4);
    buf model = model_of(&graph);
    long long dims[8];
    int n = vf_onnx_input_dims(model.data, model.size, dims, 8);
    CHECK(n == 4 && dims[0] == -1 && dims[1] == 3 && dims[2] == 160 && dims[3] == 160,
          "input [N,3,160,160] found past the weight (%d dims)", n);
    /* every truncation of the message is handled: no dims or a prefix, never a crash */
    int worst = 0;
    for (size_t cut = 0; cut < model.size; cut++)
        worst = vf_onnx_input_dims(model.data, cut, dims, 8) > 4 ? 1 : worst;
    CHECK(!worst, "truncated models give at most the real dims");
    CHECK(vf_onnx_input_dims((const unsigned char *)"hello", 5, dims, 8) == 0, "not ONNX");
    free(model.data);
}

static void test_many_inputs(void)
{
    enum { WEIGHTS = 20000 };
    buf graph = {0};
    char name[32];
    const long long weight[1] = {64}, image[4] = {1, 3, 224, 224};
    for (int i = 0; i < WEIGHTS; i++) {
        snprintf(name, sizeof name, "layer%d.weight", i);
        put_initializer(&graph, name);
    }
    for (int i = WEIGHTS - 1; i >= 0; i--) {
        snprintf(name, sizeof name, "layer%d.weight", i);
        put_input(&graph, name, weight, 1);
    }
    put_input(&graph, "image", image, 4);
    buf model = model_of(&graph);
    long long dims[8];
    double t0 = vf_now();
    int n = vf_onnx_input_dims(model.data, model.size, dims, 8);
    double seconds = vf_now() - t0;
    CHECK(n == 4 && dims[2] == 224, "the image input after %d weights (%d dims)", WEIGHTS, n);
    CHECK(seconds < 1.0, "%d listed weights walked in %.2f s (%.1f MB)", WEIGHTS, seconds,
          model.size / 1e6);
    free(model.data);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_small);
    CHECK_CASE(test_many_inputs);
    return check_finish();
}
