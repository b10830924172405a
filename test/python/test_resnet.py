"""norm2tex.resnet: torchvision's ResNet-18 with random weights, on torchvision before and after
0.13 (pretrained=False became weights=None; Debian 11 ships 0.8, Debian 12 0.14), and an error
naming the package to install where torchvision is missing. The old and new interfaces are
simulated with stand-ins for torchvision.models, so both run on any machine.

Run (with the workspace sourced): /usr/bin/python3 -m pytest -q test/python/test_resnet.py
"""
import sys
import types

import pytest

torch = pytest.importorskip("torch", reason="PyTorch is not installed (Debian: python3-torch)")

from norm2tex import resnet  # noqa: E402


def test_resnet18_is_torchvisions_with_random_weights():
    torchvision = pytest.importorskip(
        "torchvision", reason="torchvision is not installed (Debian: python3-torchvision)")
    torch.manual_seed(0)
    a = resnet.resnet18(num_classes=7)
    torch.manual_seed(1)
    b = resnet.resnet18(num_classes=7)
    assert type(a) is torchvision.models.ResNet and a.fc.out_features == 7
    # Randomly initialised: another seed, other weights (pretrained ones would be equal).
    assert not torch.equal(a.conv1.weight, b.conv1.weight)


def fake_torchvision(monkeypatch, resnet18):
    models = types.SimpleNamespace(resnet18=resnet18)
    monkeypatch.setitem(sys.modules, "torchvision", types.SimpleNamespace(models=models))
    monkeypatch.setitem(sys.modules, "torchvision.models", models)


def test_resnet18_on_torchvision_before_0_13(monkeypatch):
    # Debian 11's torchvision 0.8: resnet18(pretrained=False, progress=True, **kwargs).
    calls = []

    def resnet18(pretrained=False, progress=True, **kwargs):
        calls.append(dict(kwargs, pretrained=pretrained))
        return "a ResNet"

    fake_torchvision(monkeypatch, resnet18)
    assert resnet.resnet18(num_classes=3) == "a ResNet"
    assert calls == [{"num_classes": 3, "pretrained": False}]


def test_resnet18_on_torchvision_0_13_and_later(monkeypatch):
    calls = []

    def resnet18(*, weights=None, progress=True, **kwargs):
        calls.append(dict(kwargs, weights=weights))
        return "a ResNet"

    fake_torchvision(monkeypatch, resnet18)
    assert resnet.resnet18(num_classes=3) == "a ResNet"
    assert calls == [{"num_classes": 3, "weights": None}]


def test_without_torchvision_the_error_names_the_package(monkeypatch):
    monkeypatch.setitem(sys.modules, "torchvision", None)  # what "not installed" looks like
    with pytest.raises(ImportError, match="apt-get install python3-torchvision"):
        resnet.resnet18(num_classes=3)
