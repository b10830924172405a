"""norm2tex.torch_device.resolve_device, the one device rule of the package's training tools:
"auto" takes CUDA when PyTorch sees a GPU, else the CPU; a device asked for by name is used or
refused with an error naming it and what PyTorch sees, never replaced by the CPU. Whether a GPU
is there is simulated (torch.cuda's answers patched), so every case runs on any machine.

Run (with the workspace sourced): /usr/bin/python3 -m pytest -q test/python/test_torch_device.py
"""
import pytest

torch = pytest.importorskip("torch", reason="PyTorch is not installed (Debian: python3-torch)")

from norm2tex.torch_device import (  # noqa: E402
    DeviceUnavailable, available_devices, resolve_device)


@pytest.fixture
def gpus(monkeypatch):
    """gpus(n): PyTorch sees n CUDA GPUs from now on in this test."""
    def see(n):
        monkeypatch.setattr(torch.cuda, "is_available", lambda: n > 0)
        monkeypatch.setattr(torch.cuda, "device_count", lambda: n)
    return see


def test_auto_takes_cuda_when_there_is_a_gpu_else_the_cpu(gpus):
    gpus(0)
    assert resolve_device() == resolve_device("auto") == "cpu"
    assert available_devices() == ["cpu"]
    gpus(2)
    assert resolve_device() == resolve_device("auto") == "cuda"
    assert available_devices() == ["cpu", "cuda:0", "cuda:1"]


def test_a_device_named_is_used_when_it_is_there(gpus):
    gpus(2)
    assert resolve_device("cpu") == "cpu"
    assert resolve_device("cuda") == "cuda"
    assert resolve_device("cuda:1") == "cuda:1"


def test_a_device_named_that_is_not_there_is_an_error_not_the_cpu(gpus):
    gpus(0)
    with pytest.raises(DeviceUnavailable, match=r"'cuda' was asked for, but PyTorch sees no "
                       r"CUDA GPU .*available: cpu"):
        resolve_device("cuda")
    gpus(2)
    with pytest.raises(DeviceUnavailable, match=r"'cuda:2' was asked for, but PyTorch sees 2 "
                       r"CUDA GPUs; available: cpu, cuda:0, cuda:1"):
        resolve_device("cuda:2")
    assert issubclass(DeviceUnavailable, RuntimeError)


def test_what_is_not_a_device_is_refused():
    for bad in ("gpu", "", "cuda:x"):
        with pytest.raises(ValueError, match="not a device name: auto, cpu, cuda or cuda:N"):
            resolve_device(bad)
    with pytest.raises(ValueError, match="only the CPU and CUDA GPUs"):
        resolve_device("xla")


def test_the_classifier_uses_the_rule():
    # (test_hold_cube_experiment.py checks the experiment's.)
    from norm2tex import classify

    assert classify.resolve_device is resolve_device
