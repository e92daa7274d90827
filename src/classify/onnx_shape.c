/* A minimal protobuf walker, just enough to read an ONNX model's input shape. */
#include "onnx_shape.h"

#include <stdlib.h>
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

/* Order of names: by length, then bytes (for qsort and bsearch). */
static int compare_names(const void *pa, const void *pb)
{
    const pb_reader *a = pa, *b = pb;
    size_t na = (size_t)(a->end - a->p), nb = (size_t)(b->end - b->p);
    if (na != nb)
        return na < nb ? -1 : 1;
    return na ? memcmp(a->p, b->p, na) : 0;
}

/* The names of the graph's initializers, sorted (*count of them; NULL when none or out of
 * memory, which only costs the skipping below). Older exporters also list every weight among
 * the inputs, so a model can have thousands of each: one sorted list keeps this n log n. */
static pb_reader *initializer_names(pb_reader graph, size_t *count)
{
    pb_field f;
    size_t n = 0, cap = 0;
    pb_reader *names = NULL;
    *count = 0;
    while (pb_next(&graph, &f)) {
        if (f.number != GRAPH_INITIALIZER || f.wire != 2)
            continue;
        if (n == cap) {
            size_t grown_cap = cap ? 2 * cap : 64;
            pb_reader *grown = realloc(names, grown_cap * sizeof *names);
            if (!grown)
                break;
            names = grown;
            cap = grown_cap;
        }
        names[n++] = pb_find(f.sub, TENSOR_NAME);
    }
    if (n)
        qsort(names, n, sizeof *names, compare_names);
    *count = n;
    return names;
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
    size_t init_count;
    pb_reader *inits = initializer_names(graph, &init_count);
    pb_reader inputs = graph;
    pb_field f;
    int found = 0;
    while (pb_next(&inputs, &f)) {
        if (f.number != GRAPH_INPUT || f.wire != 2)
            continue;
        pb_reader name = pb_find(f.sub, VALUE_INFO_NAME);
        if (!inits || !bsearch(&name, inits, init_count, sizeof *inits, compare_names)) {
            found = read_dims(f.sub, dims, max);
            break;
        }
    }
    free(inits);
    return found;
}
