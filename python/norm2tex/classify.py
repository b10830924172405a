"""Material classification from tactile frames: the models and the held-out-variant experiment
of ``scripts/train_material_classifier`` (needs PyTorch, and torchvision for ResNet-18; imported
on its own, not by ``import norm2tex``).

The input is a background-subtracted frame (``ExportedDataset(image="diff")``: float grey
levels, 3 x rows x cols BGR: 3 x 320 x 240 for a QVGA DIGIT), averaged over ``downscale`` x ``downscale`` pixel
blocks before the network. At 0.053 mm/px a 4x average has 0.21 mm pixels, the period of a
0.2 mm 3-D print layer: averaging removes every pattern whose period is not longer than the
block (a 2-px stripe vanishes at 2x and 4x), so ``downscale`` sets what the classifier can see.

    from norm2tex.classify import run
    result = run("/data/all_png", test_variants=[3], downscale=2)
    result["overall"]["accuracy"], result["confusion"]

``run`` returns every number as plain Python values (what ``--json`` writes).
"""

import platform
import time

import torch
import torch.nn as nn
import torch.nn.functional as F

from norm2tex.blocks import CHANNELS_FIRST, block_mean
from norm2tex.resnet import resnet18
from norm2tex.torch_device import resolve_device

ARCHS = ("small", "resnet18")
DOWNSCALES = (1, 2, 4)
# The diff frames are grey-level differences of a few tens; this brings them near unit scale.
INPUT_SCALE = 32.0


class Downscale(nn.Module):
    """Scales the diff frame to ~unit values and averages it over factor x factor blocks
    (norm2tex.block_mean: rows and columns past the last whole block are dropped)."""

    def __init__(self, factor):
        super().__init__()
        if factor not in DOWNSCALES:
            raise ValueError(f"downscale must be one of {DOWNSCALES}, not {factor!r}")
        self.factor = factor

    def forward(self, x):
        return block_mean(x / INPUT_SCALE, self.factor, axes=CHANNELS_FIRST)


class SmallTactileNet(nn.Module):
    """Three convolutions (16, 32, 64 channels), global average pooling, a linear layer."""

    def __init__(self, classes, downscale=4, channels=3):
        super().__init__()
        self.downscale = Downscale(downscale)
        self.conv1 = nn.Conv2d(channels, 16, 5, padding=2)
        self.conv2 = nn.Conv2d(16, 32, 3, padding=1)
        self.conv3 = nn.Conv2d(32, 64, 3, padding=1)
        self.fc = nn.Linear(64, classes)

    def forward(self, x):
        x = self.downscale(x)
        x = F.max_pool2d(F.relu(self.conv1(x)), 2)
        x = F.max_pool2d(F.relu(self.conv2(x)), 2)
        x = F.relu(self.conv3(x))
        return self.fc(x.mean(dim=(2, 3)))


class ResNet18(nn.Module):
    """torchvision's ResNet-18 (BasicBlock, [2, 2, 2, 2], 64-512 channels), randomly initialised
    (no pretrained weights), after the same input averaging as the small net; its stem takes
    `channels` input channels and its last layer gives `classes` logits. The paper's classifier
    architecture; ~11 M parameters, meant for a GPU."""

    def __init__(self, classes, downscale=4, channels=3):
        super().__init__()
        self.downscale = Downscale(downscale)
        self.net = resnet18(num_classes=classes)
        if channels != self.net.conv1.in_channels:
            self.net.conv1 = _stem(channels, self.net.conv1)

    def forward(self, x):
        return self.net(self.downscale(x))


def _stem(channels, conv):
    """`conv` (torchvision's 7x7 stride-2 stem) for `channels` input channels, initialised as
    torchvision initialises its convolutions."""
    stem = nn.Conv2d(channels, conv.out_channels, conv.kernel_size, stride=conv.stride,
                     padding=conv.padding, bias=False)
    nn.init.kaiming_normal_(stem.weight, mode="fan_out", nonlinearity="relu")
    return stem


def use_deterministic_kernels():
    """Deterministic kernels where this PyTorch can ask for them without failing on an op that
    has none (torch.use_deterministic_algorithms(..., warn_only=True), 1.11 on; Debian 11's 1.7
    has neither): on a CPU the ops used here are deterministic anyway, so older versions skip it."""
    try:
        torch.use_deterministic_algorithms(True, warn_only=True)
    except (AttributeError, TypeError):
        pass


def build_model(arch, classes, downscale=4, channels=3):
    """The named architecture ("small" or "resnet18") for `classes` classes."""
    if arch == "small":
        return SmallTactileNet(classes, downscale, channels)
    if arch == "resnet18":
        return ResNet18(classes, downscale, channels)
    raise ValueError(f"unknown arch {arch!r}: choose one of {', '.join(ARCHS)}")


def split(export_dir, test_variants):
    """(train, test, classes): ExportedDataset of the variants not held out and of the held-out
    ones. Raises ValueError when no frame is held out or no variant is left to train on."""
    from norm2tex_dataset import ExportedDataset

    held_out = sorted(set(int(v) for v in test_variants))
    everything = ExportedDataset(export_dir, image="diff")
    variants = sorted({r["variant"] for r in everything.rows})
    train_variants = [v for v in variants if v not in held_out]
    if not any(v in variants for v in held_out):
        raise ValueError(f"no frames of the held-out variants {held_out} in {export_dir} "
                         f"(it holds variants {variants})")
    if not train_variants:
        raise ValueError(f"no variant left to train on: {export_dir} holds only variants "
                         f"{variants}, all held out; record more variants")
    train = ExportedDataset(export_dir, image="diff", variants=train_variants)
    test = ExportedDataset(export_dir, image="diff", variants=held_out)
    # Both splits index classes by the full dataset's materials, so their targets agree.
    return train, test, everything.classes


def _per_material(dataset, classes):
    counts = {c: 0 for c in classes}
    for row in dataset.rows:
        counts[row["material"]] += 1
    return counts


def confusion_matrix(model, loader, classes, device):
    """confusion[true][predicted] counts over the loader."""
    model.eval()
    confusion = [[0] * classes for _ in range(classes)]
    with torch.no_grad():
        for images, targets in loader:
            predicted = model(images.to(device)).argmax(1).cpu()
            for p, t in zip(predicted.tolist(), targets.tolist()):
                confusion[t][p] += 1
    return confusion


def run(export_dir, test_variants=(3,), epochs=12, seed=0, downscale=4, arch="small",
        device="auto", threads=2, batch_size=32, lr=2e-3, workers=2, log=print):
    """Trains `arch` on the variants not in `test_variants`, tests on those, returns a dict of
    settings, frame counts, per-epoch loss and training accuracy, the confusion matrix
    (rows: true material, columns: predicted), per-material and overall held-out accuracy and
    the training wall time. The same seed gives the same result on the same machine (model
    initialisation and the shuffled data order both come from it)."""
    if arch not in ARCHS:
        raise ValueError(f"unknown arch {arch!r}: choose one of {', '.join(ARCHS)}")
    if downscale not in DOWNSCALES:
        raise ValueError(f"downscale must be one of {DOWNSCALES}, not {downscale!r}")
    device = resolve_device(device)  # "auto": cuda when PyTorch sees a GPU, else cpu
    if threads:
        torch.set_num_threads(threads)
    torch.manual_seed(seed)
    use_deterministic_kernels()
    on_gpu = device.startswith("cuda")
    if on_gpu:
        torch.backends.cudnn.benchmark = False
    train, test, classes = split(export_dir, test_variants)
    train_variants = sorted({r["variant"] for r in train.rows})
    held_out = sorted({r["variant"] for r in test.rows})
    log(f"{len(train)} training frames (variants {train_variants}), {len(test)} held-out "
        f"(variants {held_out}); classes {classes}; {arch}, {downscale}x averaging, {device}")
    order = torch.Generator().manual_seed(seed)
    train_loader = torch.utils.data.DataLoader(train, batch_size=batch_size, shuffle=True,
                                               generator=order, num_workers=workers,
                                               pin_memory=on_gpu)
    test_loader = torch.utils.data.DataLoader(test, batch_size=64, num_workers=workers,
                                              pin_memory=on_gpu)
    model = build_model(arch, len(classes), downscale).to(device)
    optimiser = torch.optim.Adam(model.parameters(), lr=lr)
    history = []
    start = time.time()
    for epoch in range(epochs):
        model.train()
        loss_sum, right, seen = 0.0, 0, 0
        for images, targets in train_loader:
            images, targets = images.to(device), targets.to(device)
            optimiser.zero_grad()
            logits = model(images)
            loss = F.cross_entropy(logits, targets)
            loss.backward()
            optimiser.step()
            loss_sum += loss.item() * len(targets)
            right += (logits.argmax(1) == targets).sum().item()
            seen += len(targets)
        history.append({"epoch": epoch + 1, "loss": loss_sum / seen, "train_accuracy": right / seen})
        log(f"epoch {epoch + 1:2d}: loss {loss_sum / seen:.3f}, training accuracy "
            f"{right / seen:.3f} ({time.time() - start:.0f} s)")
    train_time = time.time() - start
    confusion = confusion_matrix(model, test_loader, len(classes), device)
    per_material = {}
    for i, name in enumerate(classes):
        total = sum(confusion[i])
        per_material[name] = {"correct": confusion[i][i], "total": total,
                              "accuracy": confusion[i][i] / total if total else None}
    correct = sum(confusion[i][i] for i in range(len(classes)))
    total = sum(map(sum, confusion))
    sample, _ = test[0]
    return {
        "settings": {
            "export_dir": str(export_dir), "arch": arch, "downscale": downscale,
            "input_size": [sample.shape[1] // downscale, sample.shape[2] // downscale],
            "frame_size": list(sample.shape[1:]), "epochs": epochs, "seed": seed,
            "test_variants": held_out, "train_variants": train_variants, "device": device,
            "threads": torch.get_num_threads(), "batch_size": batch_size, "lr": lr,
            "workers": workers, "parameters": sum(p.numel() for p in model.parameters()),
            "torch": torch.__version__, "machine": platform.node(),
        },
        "classes": classes,
        "frames": {"train": len(train), "test": len(test),
                   "train_per_material": _per_material(train, classes),
                   "test_per_material": _per_material(test, classes)},
        "history": history,
        "confusion": confusion,
        "per_material": per_material,
        "overall": {"correct": correct, "total": total, "accuracy": correct / total},
        "chance": 1.0 / len(classes),
        "train_time_s": train_time,
    }


def format_confusion(result):
    """The confusion matrix as text: rows the true material, columns the predicted one."""
    classes = result["classes"]
    width = max(8, max(len(c) for c in classes) + 1)
    lines = ["true \\ predicted".ljust(width) + "".join(c[:width - 1].rjust(width) for c in classes)]
    for name, row in zip(classes, result["confusion"]):
        lines.append(name.ljust(width) + "".join(str(n).rjust(width) for n in row))
    return "\n".join(lines)
