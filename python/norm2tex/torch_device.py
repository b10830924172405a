"""Which PyTorch device the package's training runs on: one rule for every tool.

"auto" (or None) takes CUDA when PyTorch sees a GPU and the CPU otherwise. A device named
explicitly ("cpu", "cuda", "cuda:N") is used as asked or refused with an error naming what was
asked and what PyTorch sees: a run asked to use a GPU never slips onto the CPU unnoticed.

    from norm2tex.torch_device import resolve_device
    device = resolve_device(args.device)   # "cpu", "cuda" or "cuda:N"
"""

import torch

AUTO = "auto"
# The --device help of every script that trains (one wording for one behaviour).
HELP = ("auto (default): cuda when PyTorch sees a GPU, else cpu; cpu, cuda or cuda:N: that "
        "device, an error when PyTorch does not see it")


class DeviceUnavailable(RuntimeError):
    """A device was asked for by name and PyTorch does not see it."""


def available_devices():
    """The devices PyTorch sees here, as resolve_device spells them: "cpu", "cuda:0", ..."""
    gpus = torch.cuda.device_count() if torch.cuda.is_available() else 0
    return ["cpu"] + ["cuda:%d" % i for i in range(gpus)]


def resolve_device(device=None):
    """The device to run on, as a string torch accepts.

    None or "auto": "cuda" when PyTorch sees a GPU, else "cpu". "cpu", "cuda" or "cuda:N": that
    device. Raises DeviceUnavailable (a RuntimeError) when the device asked for is not there,
    naming it and the available ones, and ValueError for a name that is not a device (or a
    device type other than cpu and cuda)."""
    if device is None or device == AUTO:
        return "cuda" if torch.cuda.is_available() else "cpu"
    parsed = _parse(device)
    if parsed.type == "cpu":
        return "cpu"
    available = available_devices()
    gpus = len(available) - 1
    if gpus == 0 or (parsed.index is not None and parsed.index >= gpus):
        sees = ("no CUDA GPU (torch.cuda.is_available() is False)" if gpus == 0 else
                "%d CUDA GPU%s" % (gpus, "" if gpus == 1 else "s"))
        raise DeviceUnavailable("device %r was asked for, but PyTorch sees %s; available: %s "
                                "(or auto)" % (device, sees, ", ".join(available)))
    return str(parsed)


def _parse(device):
    """torch.device(device), or ValueError naming the spellings resolve_device takes."""
    valid = "auto, cpu, cuda or cuda:N"
    try:
        parsed = torch.device(device)
    except (RuntimeError, TypeError, ValueError) as e:
        raise ValueError("device %r is not a device name: %s" % (device, valid)) from e
    if parsed.type not in ("cpu", "cuda"):
        raise ValueError("device %r: only the CPU and CUDA GPUs are supported (%s)" %
                         (device, valid))
    return parsed
