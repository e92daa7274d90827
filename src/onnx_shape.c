/* A minimal protobuf walker, just enough to read an ONNX model's input shape. */
#include "onnx_shape.h"

#include <string.h>

/* Field numbers from onnx.proto. */
enum {
    MODEL_GRAPH = 7,
    GRAPH_INITIALIZER = 5,
    GRAPH_INPUT = 11,
    TENSOR_NAME = 8,
    VALUE_INFO_NAME = 1,
    VALUE_INFO_TYPE = 2,
    TYPE_TENSOR = 1,
    TENSOR_TYPE_SHAPE = 2,
    SHAPE_DIM = 1,
    DIM_VALUE = 1
};

typedef struct pb_reader {
    const unsigned char *p, *end;
} pb_reader;

typedef struct pb_field {
    int number, wire;
    unsigned long long value; /* varint fields */
    pb_reader sub;            /* length-delimited fields */
} pb_field;

static int pb_varint(pb_reader *r, unsigned long long *value)
{
    unsigned long long x = 0;
    for (int shift = 0; shift < 64 && r->p < r->end; shift += 7) {
        unsigned char byte = *r->p++;
        x |= (unsigned long long)(byte & 0x7f) << shift;
        if (!(byte & 0x80)) {
            *value = x;
            return 1;
        }
    }
    return 0;
}

/* Read the next field of a message; 0 at its end or on malformed data. */
static int pb_next(pb_reader *r, pb_field *f)
{
    unsigned long long key, len;
    if (r->p >= r->end || !pb_varint(r, &key))
        return 0;
    f->number = (int)(key >> 3);
    f->wire = (int)(key & 7);
    size_t left = (size_t)(r->end - r->p);
    switch (f->wire) {
    case 0:
        return pb_varint(r, &f->value);
    case 1: /* fixed 64-bit */
    case 5: /* fixed 32-bit */
        len = f->wire == 1 ? 8 : 4;
        break;
    case 2:
        if (!pb_varint(r, &len))
            return 0;
        left = (size_t)(r->end - r->p);
        f->sub = (pb_reader){r->p, r->p + (len <= left ? len : 0)};
        break;
    default:
        return 0;
    }
    if (len > left)
        return 0;
    r->p += len;
    return 1;
}

/* The first length-delimited field `number` of a message (empty when absent). */
static pb_reader pb_find(pb_reader msg, int number)
{
    pb_field f;
    while (pb_next(&msg, &f))
        if (f.number == number && f.wire == 2)
            return f.sub;
    return (pb_reader){NULL, NULL};
}

static int same_bytes(pb_reader a, pb_reader b)
{
    size_t n = (size_t)(a.end - a.p);
    return n == (size_t)(b.end - b.p) && (n == 0 || memcmp(a.p, b.p, n) == 0);
}

/* Older exporters list the weights among the graph inputs too: skip those. */
static int is_initializer(pb_reader graph, pb_reader name)
{
    pb_field f;
    while (pb_next(&graph, &f))
        if (f.number == GRAPH_INITIALIZER && f.wire == 2 &&
            same_bytes(pb_find(f.sub, TENSOR_NAME), name))
            return 1;
    return 0;
}

static int read_dims(pb_reader value_info, long long *dims, int max)
{
    pb_reader type = pb_find(value_info, VALUE_INFO_TYPE);
    pb_reader shape = pb_find(pb_find(type, TYPE_TENSOR), TENSOR_TYPE_SHAPE);
    pb_field f, g;
    int count = 0;
    while (count < max && pb_next(&shape, &f)) {
        if (f.number != SHAPE_DIM || f.wire != 2)
            continue;
        dims[count] = -1;
        while (pb_next(&f.sub, &g))
            if (g.number == DIM_VALUE && g.wire == 0)
                dims[count] = (long long)g.value;
        count++;
    }
    return count;
}

int vf_onnx_input_dims(const unsigned char *data, size_t size, long long *dims, int max)
{
    pb_reader graph = pb_find((pb_reader){data, data + size}, MODEL_GRAPH);
    pb_reader inputs = graph;
    pb_field f;
    while (pb_next(&inputs, &f)) {
        if (f.number != GRAPH_INPUT || f.wire != 2)
            continue;
        if (!is_initializer(graph, pb_find(f.sub, VALUE_INFO_NAME)))
            return read_dims(f.sub, dims, max);
    }
    return 0;
}
