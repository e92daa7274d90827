#!/usr/bin/env python3
"""Small ONNX classifiers built with Debian's python3-onnx, for tests/test_data_engines.c.

Each graph holds the ops that torch.onnx.export writes for real classifiers and that OpenCV
4.6's importer refuses (Identity on weights, broadcast Mul, Mod, LayerNorm, Gelu through Erf,
Softmax, batched MatMul), maps an RGB image to 1000 logits, and has random weights. The
builder below runs every op in numpy as it adds it to the graph, so each model comes with its
own reference output, computed independently of any ONNX runtime.

    onnx_ops.py OUT_DIR

writes, per model NAME: NAME.onnx, NAME.input.bin (float32, the input batch in the model's
layout) and NAME.expected.bin (float32 logits), and OUT_DIR/models.txt with one line
"NAME N LAYOUT SIZE" per model (LAYOUT nchw or nhwc).
"""
import math
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

CLASSES = 1000
rng = np.random.default_rng(7)


class Graph:
    """An ONNX graph and, beside it, the numpy value of every tensor in it."""

    def __init__(self, name, x, layout, fixed_batch=False):
        self.name, self.nodes, self.inits, self.values = name, [], [], {}
        self.layout, self.count, self.fixed_batch = layout, 0, fixed_batch
        dims = list(x.shape)
        if not fixed_batch:
            dims[0] = "N"
        self.input = helper.make_tensor_value_info("image", TensorProto.FLOAT, dims)
        self.values["image"] = x
        self.x = "image"

    def fresh(self, what):
        self.count += 1
        return f"{what}_{self.count}"

    def weight(self, value, name=None):
        name = name or self.fresh("w")
        value = np.asarray(value, dtype=np.float32 if value.dtype.kind == "f" else value.dtype)
        self.inits.append(numpy_helper.from_array(value, name))
        self.values[name] = value
        return name

    def random(self, *shape, scale=None):
        fan_in = int(np.prod(shape[1:])) if len(shape) > 1 else shape[0]
        scale = scale or 1 / math.sqrt(fan_in)
        return self.weight(rng.normal(0, scale, shape).astype(np.float32))

    def op(self, op_type, inputs, value, **attrs):
        """Add a node whose numpy result is `value` (computed by the caller from the inputs)."""
        out = self.fresh(op_type.lower())
        self.nodes.append(helper.make_node(op_type, inputs, [out], **attrs))
        self.values[out] = np.asarray(value)
        return out

    def v(self, name):
        return self.values[name]

    # ---- ops, each with its numpy meaning ----
    def identity(self, a):
        return self.op("Identity", [a], self.v(a))

    def matmul(self, a, b):
        return self.op("MatMul", [a, b], np.matmul(self.v(a), self.v(b)).astype(np.float32))

    def add(self, a, b):
        return self.op("Add", [a, b], (self.v(a) + self.v(b)).astype(np.float32))

    def sub(self, a, b):
        return self.op("Sub", [a, b], (self.v(a) - self.v(b)).astype(np.float32))

    def mul(self, a, b):
        return self.op("Mul", [a, b], (self.v(a) * self.v(b)).astype(np.float32))

    def div(self, a, b):
        return self.op("Div", [a, b], (self.v(a) / self.v(b)).astype(np.float32))

    def sqrt(self, a):
        return self.op("Sqrt", [a], np.sqrt(self.v(a)))

    def erf(self, a):
        return self.op("Erf", [a], np.vectorize(math.erf)(self.v(a)).astype(np.float32))

    def mod(self, a, b):
        return self.op("Mod", [a, b], np.fmod(self.v(a), self.v(b)).astype(np.float32), fmod=1)

    def relu(self, a):
        return self.op("Relu", [a], np.maximum(self.v(a), 0))

    def softmax(self, a, axis=-1):
        x = self.v(a)
        e = np.exp(x - x.max(axis=axis, keepdims=True))
        return self.op("Softmax", [a], (e / e.sum(axis=axis, keepdims=True)).astype(np.float32),
                       axis=axis)

    def reduce_mean(self, a, axes):
        return self.op("ReduceMean", [a], self.v(a).mean(axis=tuple(axes), keepdims=True),
                       axes=axes, keepdims=1)

    def transpose(self, a, perm):
        return self.op("Transpose", [a], np.transpose(self.v(a), perm), perm=perm)

    def reshape(self, a, shape):
        """shape may use 0 (copy that dimension) and -1, as ONNX Reshape does."""
        x = self.v(a)
        real = [x.shape[i] if d == 0 else d for i, d in enumerate(shape)]
        return self.op("Reshape", [a, self.weight(np.array(shape, dtype=np.int64))],
                       x.reshape(real))

    def flatten(self, a):
        x = self.v(a)
        return self.op("Flatten", [a], x.reshape(x.shape[0], -1), axis=1)

    def conv(self, a, w, stride=1):
        x, k = self.v(a), self.v(w)
        n, c, h, wd = x.shape
        o, _, kh, kw = k.shape
        oh, ow = (h - kh) // stride + 1, (wd - kw) // stride + 1
        out = np.zeros((n, o, oh, ow), np.float32)
        for i in range(oh):
            for j in range(ow):
                patch = x[:, :, i * stride:i * stride + kh, j * stride:j * stride + kw]
                out[:, :, i, j] = np.tensordot(patch, k, axes=([1, 2, 3], [1, 2, 3]))
        return self.op("Conv", [a, w], out, strides=[stride, stride], kernel_shape=[kh, kw])

    def global_average_pool(self, a):
        return self.op("GlobalAveragePool", [a], self.v(a).mean(axis=(2, 3), keepdims=True))

    def gather(self, a, index, axis):
        return self.op("Gather", [a, self.weight(np.array(index, dtype=np.int64))],
                       np.take(self.v(a), index, axis=axis), axis=axis)

    def concat(self, names, axis):
        return self.op("Concat", names, np.concatenate([self.v(n) for n in names], axis=axis),
                       axis=axis)

    def expand_batch(self, token, like):
        """token [1,...] repeated over the batch of `like` (Shape, Gather, Concat, Expand)."""
        n = self.v(like).shape[0]
        shape = self.op("Shape", [like], np.array(self.v(like).shape, dtype=np.int64))
        batch = self.op("Gather", [shape, self.weight(np.array([0], dtype=np.int64))],
                        np.array([n], dtype=np.int64), axis=0)
        rest = self.weight(np.array(self.v(token).shape[1:], dtype=np.int64))
        target = self.op("Concat", [batch, rest],
                         np.array([n, *self.v(token).shape[1:]], dtype=np.int64), axis=0)
        return self.op("Expand", [token, target],
                       np.broadcast_to(self.v(token), (n, *self.v(token).shape[1:])))

    # ---- blocks as torch exports them ----
    def layer_norm(self, a, width):
        """opset-17 LayerNormalization over the last axis."""
        x = self.v(a)
        g, b = self.random(width, scale=1), self.random(width, scale=0.1)
        mean = x.mean(-1, keepdims=True)
        var = ((x - mean) ** 2).mean(-1, keepdims=True)
        y = (x - mean) / np.sqrt(var + 1e-5) * self.v(g) + self.v(b)
        return self.op("LayerNormalization", [a, g, b], y.astype(np.float32), axis=-1,
                       epsilon=1e-5)

    def layer_norm_2d(self, a, channels):
        """ConvNeXt's LayerNorm2d: mean and variance over channels, written out with Div."""
        mean = self.reduce_mean(a, [1])
        centred = self.sub(a, mean)
        var = self.reduce_mean(self.mul(centred, centred), [1])
        eps = self.weight(np.array(1e-6, dtype=np.float32))
        normed = self.div(centred, self.sqrt(self.add(var, eps)))
        scale = self.random(channels, 1, 1, scale=1)
        return self.add(self.mul(normed, scale), self.random(channels, 1, 1, scale=0.1))

    def gelu(self, a):
        """0.5 x (1 + erf(x / sqrt 2)), as torch exports nn.GELU at opset < 20."""
        inner = self.erf(self.div(a, self.weight(np.array(math.sqrt(2), dtype=np.float32))))
        one = self.weight(np.array(1, dtype=np.float32))
        half = self.weight(np.array(0.5, dtype=np.float32))
        return self.mul(self.mul(a, self.add(inner, one)), half)

    def head(self, a):
        """Flatten (when needed) and a linear layer to the 1000 classes."""
        if self.v(a).ndim > 2:
            a = self.flatten(a)
        w = self.random(self.v(a).shape[1], CLASSES)
        return self.add(self.matmul(a, w), self.random(CLASSES, scale=0.1))

    def save(self, out_dir, logits):
        output = helper.make_tensor_value_info(logits, TensorProto.FLOAT, [1 if self.fixed_batch else "N", CLASSES])
        graph = helper.make_graph(self.nodes, self.name, [self.input], [output], self.inits)
        model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)],
                                  producer_name="vfcapture tests/onnx_ops.py")
        model.ir_version = 8
        onnx.checker.check_model(model)
        onnx.save(model, os.path.join(out_dir, self.name + ".onnx"))
        self.values["image"].astype(np.float32).tofile(os.path.join(out_dir, self.name + ".input.bin"))
        self.v(logits).astype(np.float32).tofile(os.path.join(out_dir, self.name + ".expected.bin"))
        n, size = self.values["image"].shape[0], self.values["image"].shape[2]
        return f"{self.name} {n} {self.layout} {size}"


def image(n=2, size=16, layout="nchw"):
    x = rng.normal(0, 1, (n, 3, size, size)).astype(np.float32)
    return x if layout == "nchw" else np.ascontiguousarray(x.transpose(0, 2, 3, 1))


def identity_weights():
    """Shared weights reached through Identity nodes (every torchvision ResNet export)."""
    g = Graph("identity_weights", image(), "nchw")
    w = g.random(8, 3, 3, 3)
    h = g.relu(g.conv(g.x, g.identity(w)))
    h = g.relu(g.conv(h, g.identity(g.random(8, 8, 3, 3))))
    return g, g.head(g.global_average_pool(h))


def broadcast_mul():
    """[N,3,S,S] * [3,1,1] and [N,T,D] * [D] (ViT's scaled attention and layer scale)."""
    g = Graph("broadcast_mul", image(), "nchw")
    h = g.mul(g.x, g.random(3, 1, 1, scale=1))
    tokens = g.transpose(g.reshape(h, [0, 3, -1]), [0, 2, 1])
    tokens = g.mul(tokens, g.random(3, scale=1))
    return g, g.head(tokens)


def mod():
    """Mod with fmod=1 (Swin's window shifts use Mod)."""
    g = Graph("mod", image(), "nchw")
    return g, g.head(g.mod(g.x, g.weight(np.array(0.7, dtype=np.float32))))


def layernorm():
    """LayerNormalization over tokens, and ConvNeXt's LayerNorm2d written with Div."""
    g = Graph("layernorm", image(), "nchw")
    h = g.layer_norm_2d(g.conv(g.x, g.random(8, 3, 2, 2), stride=2), 8)
    tokens = g.transpose(g.reshape(h, [0, 8, -1]), [0, 2, 1])
    return g, g.head(g.layer_norm(tokens, 8))


def gelu_erf():
    g = Graph("gelu_erf", image(), "nchw")
    return g, g.head(g.gelu(g.flatten(g.x)))


def softmax_matmul():
    """Attention: batched MatMul of [N,T,D] by [N,D,T], Softmax, MatMul by [N,T,D]."""
    g = Graph("softmax_matmul", image(), "nchw")
    tokens = g.transpose(g.reshape(g.x, [0, 3, -1]), [0, 2, 1])  # [N,256,3]
    keys = g.transpose(tokens, [0, 2, 1])
    attention = g.softmax(g.matmul(tokens, keys))
    return g, g.head(g.matmul(attention, tokens))


def tiny_vit():
    """A one-block vision transformer: patches, class token, positions, two-head attention,
    GELU MLP, LayerNorms, the class token's logits (the shape of ViT-B/16, very small)."""
    g = Graph("tiny_vit", image(size=32), "nchw")
    dim, heads = 16, 2
    patches = g.conv(g.x, g.random(dim, 3, 8, 8), stride=8)  # [N,16,4,4]
    tokens = g.transpose(g.reshape(patches, [0, dim, -1]), [0, 2, 1])  # [N,16,dim]
    cls = g.expand_batch(g.random(1, 1, dim, scale=1), tokens)
    tokens = g.add(g.concat([cls, tokens], 1), g.random(1, 17, dim, scale=0.5))
    h = g.layer_norm(tokens, dim)

    def split_heads(t):
        return g.transpose(g.reshape(t, [0, 17, heads, dim // heads]), [0, 2, 1, 3])

    q = split_heads(g.matmul(h, g.random(dim, dim)))
    k = split_heads(g.matmul(h, g.random(dim, dim)))
    v = split_heads(g.matmul(h, g.random(dim, dim)))
    scores = g.mul(g.matmul(q, g.transpose(k, [0, 1, 3, 2])),
                   g.weight(np.array(1 / math.sqrt(dim // heads), dtype=np.float32)))
    mixed = g.matmul(g.softmax(scores), v)  # [N,heads,17,dh]
    merged = g.reshape(g.transpose(mixed, [0, 2, 1, 3]), [0, 17, dim])
    tokens = g.add(tokens, g.matmul(merged, g.random(dim, dim)))
    mlp = g.matmul(g.gelu(g.matmul(g.layer_norm(tokens, dim), g.random(dim, 4 * dim))),
                   g.random(4 * dim, dim))
    tokens = g.add(tokens, mlp)
    first = g.gather(g.layer_norm(tokens, dim), 0, axis=1)  # [N,dim]
    return g, g.head(first)


def nhwc():
    """A TensorFlow-style model that takes [N,S,S,3]."""
    g = Graph("nhwc", image(layout="nhwc"), "nhwc")
    h = g.transpose(g.x, [0, 3, 1, 2])
    return g, g.head(g.global_average_pool(g.relu(g.conv(h, g.random(8, 3, 3, 3)))))


def fixed_batch():
    """An export with batch size fixed at 1 (the engine runs a batch one input at a time)."""
    g = Graph("fixed_batch", image(n=1), "nchw", fixed_batch=True)
    return g, g.head(g.global_average_pool(g.conv(g.x, g.random(8, 3, 3, 3))))


def unknown_op(out_dir):
    """A graph with an op no runtime has (the load error must name it); not in models.txt."""
    node = helper.make_node("VfNoSuchOp", ["image"], ["logits"], domain="vf.test")
    graph = helper.make_graph(
        [node], "unknown_op",
        [helper.make_tensor_value_info("image", TensorProto.FLOAT, ["N", 3, 16, 16])],
        [helper.make_tensor_value_info("logits", TensorProto.FLOAT, ["N", CLASSES])])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17),
                                                    helper.make_opsetid("vf.test", 1)])
    model.ir_version = 8
    onnx.save(model, os.path.join(out_dir, "unknown_op.onnx"))


def main():
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    lines = []
    for build in (identity_weights, broadcast_mul, mod, layernorm, gelu_erf, softmax_matmul,
                  tiny_vit, nhwc, fixed_batch):
        g, logits = build()
        lines.append(g.save(out_dir, logits))
    unknown_op(out_dir)
    with open(os.path.join(out_dir, "models.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
