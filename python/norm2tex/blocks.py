"""Block averaging: how the package shrinks images, everywhere it does.

The environments' ``downscale`` (images, diff images and depths), the hold-images study and the
material classifier's input averaging all call ``block_mean`` (also ``norm2tex.block_mean``).
"""

import numbers
import sys

import numpy as np

# (..., rows, cols, channels): the sensor's images as numpy arrays (the default).
CHANNELS_LAST = (-3, -2)
# (..., channels, rows, cols): PyTorch's image tensors.
CHANNELS_FIRST = (-2, -1)


def block_mean(images, factor, background=None, axes=CHANNELS_LAST):
    """float32 mean of every `factor` x `factor` block of `images`, minus `background` first.

    images: a numpy array of any numeric dtype, or a torch tensor (the result stays on its
    device). axes: the rows and columns axes, CHANNELS_LAST (-3, -2) for (..., rows, cols,
    channels) images as the sensor gives them, CHANNELS_FIRST (-2, -1) for (..., channels, rows,
    cols) tensors; any other pair of axes works too. background: subtracted pixel by pixel
    before averaging; it broadcasts against images (one (rows, cols, channels) frame for a
    batch).

    A size that is not a multiple of `factor`: the rows and columns past the last whole block
    are dropped (a 61 x 47 image at factor 4 gives the 15 x 11 blocks of its first 60 x 44
    pixels), as numpy's reshape-mean of the crop and torch's avg_pool2d do. factor 1 returns the
    images (minus the background) as float32. ValueError for a factor below 1 or an image
    smaller than one block.

    bgr8 images (uint8 numpy, (rows, cols, 3) or (N, rows, cols, 3), channels last, with a
    uint8 background of one frame or none) go through the compiled core's loop: bit for bit
    the same as numpy's reshape-mean, about 20 times as fast (it was most of an environment
    step's time)."""
    ndim = len(images.shape)
    rows_axis, cols_axis = _axes(axes, ndim)
    _check_factor(factor, images.shape[rows_axis], images.shape[cols_axis])
    if _core_takes(images, background, rows_axis, cols_axis):
        from norm2tex import _core

        return _core.block_mean(images, factor, background)
    x = _float32(images)
    if background is not None:
        x = x - _float32(background, like=x)
    if factor == 1:
        return x
    first, second = sorted((rows_axis, cols_axis))
    blocks = x[_crop(x.shape, factor, first, second)].reshape(
        _block_shape(x.shape, factor, first, second))
    # After the split, `first`'s within-block axis is first + 1 and `second`'s second + 2.
    return _mean(blocks, (first + 1, second + 2))


def _axes(axes, ndim):
    """The rows and columns axes as non-negative indices, or ValueError."""
    try:
        rows_axis, cols_axis = (int(a) for a in axes)
    except (TypeError, ValueError):
        raise ValueError("block_mean: axes must be two axes (rows, cols), not %r" % (axes,))
    if not (-ndim <= rows_axis < ndim and -ndim <= cols_axis < ndim):
        raise ValueError("block_mean: axes %r outside an array of %d dimensions" % (axes, ndim))
    rows_axis, cols_axis = rows_axis % ndim, cols_axis % ndim
    if rows_axis == cols_axis:
        raise ValueError("block_mean: axes %r name one axis twice" % (axes,))
    return rows_axis, cols_axis


def _check_factor(factor, rows, cols):
    if isinstance(factor, bool) or not isinstance(factor, numbers.Integral) or factor < 1:
        raise ValueError("block_mean: factor %r; valid: an integer >= 1" % (factor,))
    if factor > rows or factor > cols:
        raise ValueError("block_mean: a %d x %d image (cols x rows) has no whole %d x %d block"
                         % (cols, rows, factor, factor))


def _core_takes(images, background, rows_axis, cols_axis):
    """Whether the compiled core's block mean applies: bgr8 frames, channels last."""
    ndim = getattr(images, "ndim", 0)
    return (isinstance(images, np.ndarray) and images.dtype == np.uint8 and ndim in (3, 4)
            and images.shape[-1] == 3 and (rows_axis, cols_axis) == (ndim - 3, ndim - 2)
            and (background is None or (isinstance(background, np.ndarray)
                                        and background.dtype == np.uint8
                                        and background.shape == images.shape[-3:])))


def _torch_tensor(array):
    """The torch module when `array` is a tensor, else None (torch is not imported for numpy)."""
    torch = sys.modules.get("torch")
    return torch if torch is not None and isinstance(array, torch.Tensor) else None


def _float32(array, like=None):
    """array as float32, a tensor on like's device when like is a tensor (no copy if it is
    already one)."""
    torch = _torch_tensor(like if like is not None else array)
    if torch is not None:
        return torch.as_tensor(array).to(device=(like if like is not None else array).device,
                                         dtype=torch.float32)
    return np.asarray(array).astype(np.float32, copy=False)


def _crop(shape, factor, first, second):
    """The index that keeps the whole blocks of axes `first` and `second`."""
    index = [slice(None)] * len(shape)
    for axis in (first, second):
        index[axis] = slice(0, shape[axis] // factor * factor)
    return tuple(index)


def _block_shape(shape, factor, first, second):
    """The cropped shape with axes `first` and `second` each split into (blocks, factor)."""
    out = []
    for axis, size in enumerate(shape):
        out += [size // factor, factor] if axis in (first, second) else [size]
    return tuple(out)


def _mean(blocks, axes):
    if _torch_tensor(blocks) is not None:
        return blocks.mean(dim=axes)
    return blocks.mean(axis=axes)
