"""torchvision's ResNet-18, randomly initialised, on every torchvision Debian ships.

The material classifier (norm2tex.classify, --arch resnet18) and the hold-the-cube policies'
image encoder (norm2tex.rl.hold_cube_experiment, --encoder resnet18) both build it here. No
pretrained weights: nothing is downloaded, the network starts from torchvision's own
initialisation.
"""

import inspect

DEBIAN_PACKAGE = "python3-torchvision"


def torchvision_models():
    """torchvision.models, or an ImportError that says which package brings it."""
    try:
        from torchvision import models
    except ImportError as e:
        raise ImportError("ResNet-18 is torchvision's and torchvision is not importable (%s): "
                          "install it (Debian and Ubuntu: apt-get install %s; elsewhere: pip "
                          "install torchvision, the release matching your torch)"
                          % (e, DEBIAN_PACKAGE)) from e
    return models


def resnet18(**kwargs):
    """torchvision.models.resnet18 with random weights; kwargs go to its ResNet (num_classes,
    norm_layer, ...)."""
    models = torchvision_models()
    # torchvision 0.13 replaced pretrained=False by weights=None (and warns about the old
    # spelling); Debian 11 ships 0.8, which knows only pretrained=.
    if "weights" in inspect.signature(models.resnet18).parameters:
        return models.resnet18(weights=None, **kwargs)
    return models.resnet18(pretrained=False, **kwargs)
