#!/usr/bin/env python3
"""Export torchvision classifiers to ONNX as a user would, for bench_classifier.

    /usr/bin/python3 bench/torchvision_models.py OUT_DIR [NAME ...]

NAME is a torchvision.models builder (default: resnet50 vit_b_16 swin_t convnext_tiny
efficientnet_b0 mobilenet_v2). Weights are random (Debian ships no pretrained ones; speed and
whether a graph loads do not depend on them), torch.onnx.export at opset 14 with a dynamic batch
axis. Beside each NAME.onnx go NAME.input.bin (a float32 batch of 2, NCHW 224) and
NAME.expected.bin (PyTorch's float32 logits for it), which bench_classifier compares each engine
against. Needs Debian's python3-torch and python3-torchvision.
"""
import os
import sys
import time

import torch
import torchvision

DEFAULT = ["resnet50", "vit_b_16", "swin_t", "convnext_tiny", "efficientnet_b0", "mobilenet_v2"]


def export(name, out_dir):
    torch.manual_seed(0)
    model = getattr(torchvision.models, name)(weights=None).eval()
    x = torch.randn(2, 3, 224, 224)
    with torch.no_grad():
        # Some builders zero their classifier head (ViT), which would make every logit 0 and
        # the comparison with PyTorch empty: give zeroed parameters small random values.
        for p in model.parameters():
            if p.dim() > 1 and not p.any():
                p.normal_(0, 0.02)
        logits = model(x)
    path = os.path.join(out_dir, name + ".onnx")
    start = time.time()
    torch.onnx.export(model, x, path, opset_version=14, input_names=["image"],
                      output_names=["logits"],
                      dynamic_axes={"image": {0: "N"}, "logits": {0: "N"}})
    x.numpy().astype("float32").tofile(os.path.join(out_dir, name + ".input.bin"))
    logits.numpy().astype("float32").tofile(os.path.join(out_dir, name + ".expected.bin"))
    print(f"{name}: {os.path.getsize(path) / 1e6:.0f} MB in {time.time() - start:.0f} s", flush=True)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    torch.set_num_threads(os.cpu_count() or 1)
    for name in sys.argv[2:] or DEFAULT:
        export(name, out_dir)


if __name__ == "__main__":
    main()
