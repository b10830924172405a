"""norm2tex.block_mean (norm2tex.blocks), the package's one block average, against a direct
numpy computation: every block's pixels averaged one block at a time, in float64. Sizes that a
factor does not divide drop the rows and columns past the last whole block. The compiled core's
path (bgr8 frames) and the numpy path agree bit for bit; torch tensors average on their device.

Run (with the workspace sourced): /usr/bin/python3 -m pytest -q test/python/test_block_mean.py
"""
import numpy as np
import pytest

import norm2tex
from norm2tex import blocks
from norm2tex.blocks import CHANNELS_FIRST, block_mean

ROWS, COLS = 61, 47  # divided by none of 2..5: every factor leaves rows and columns over


def reference(images, factor, background=None, rows_axis=-3, cols_axis=-2):
    """The mean of each whole factor x factor block, computed block by block in float64."""
    x = np.asarray(images, dtype=np.float64)
    if background is not None:
        x = x - np.asarray(background, dtype=np.float64)
    x = np.moveaxis(x, (rows_axis, cols_axis), (0, 1))
    out = np.empty((x.shape[0] // factor, x.shape[1] // factor) + x.shape[2:])
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            block = x[i * factor:(i + 1) * factor, j * factor:(j + 1) * factor]
            out[i, j] = block.mean(axis=(0, 1))
    return np.moveaxis(out, (0, 1), (rows_axis, cols_axis))


@pytest.fixture(scope="module")
def frames():
    rng = np.random.default_rng(7)
    images = rng.integers(0, 256, size=(3, ROWS, COLS, 3), dtype=np.uint8)
    background = rng.integers(0, 256, size=(ROWS, COLS, 3), dtype=np.uint8)
    return images, background


@pytest.mark.parametrize("factor", [1, 2, 3, 4, 5])
def test_equals_the_block_by_block_mean(frames, factor):
    images, background = frames
    for bg in (None, background):
        for x in (images, images.astype(np.float32) / 255.0, images[0]):
            b = None if bg is None else (bg if x.dtype == np.uint8 else bg / np.float32(255.0))
            got = block_mean(x, factor, b)
            expected = reference(x, factor, b)
            assert got.dtype == np.float32 and got.shape == expected.shape
            np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-6)


def test_a_size_the_factor_does_not_divide_drops_the_last_rows_and_columns(frames):
    images, _ = frames
    got = block_mean(images, 4)
    assert got.shape == (3, ROWS // 4, COLS // 4, 3) == (3, 15, 11, 3)
    # What lies past the last whole block (row 60, columns 44-46) changes nothing.
    changed = images.copy()
    changed[:, 60:] = 255 - changed[:, 60:]
    changed[:, :, 44:] = 255 - changed[:, :, 44:]
    assert np.array_equal(block_mean(changed, 4), got)
    assert np.array_equal(got, block_mean(images[:, :60, :44], 4))


def test_the_core_path_equals_the_numpy_path_bit_for_bit(frames):
    # bgr8 frames go through the compiled core; the same values as int16 through numpy.
    images, background = frames
    for factor in (2, 4):
        for bg in (None, background):
            wide = None if bg is None else bg.astype(np.int16)
            assert np.array_equal(block_mean(images, factor, bg),
                                  block_mean(images.astype(np.int16), factor, wide))


def test_other_axes_depths_and_channels_first(frames):
    images, _ = frames
    depths = images[..., 0].astype(np.float32) / 1000.0  # (N, rows, cols): no channel axis
    np.testing.assert_allclose(block_mean(depths, 3, axes=(-2, -1)),
                               reference(depths, 3, rows_axis=-2, cols_axis=-1), rtol=1e-6)
    first = np.ascontiguousarray(images.transpose(0, 3, 1, 2))
    assert np.array_equal(block_mean(first, 4, axes=CHANNELS_FIRST),
                          block_mean(images, 4).transpose(0, 3, 1, 2))


def test_torch_tensors_are_averaged_as_numpy_arrays(frames):
    torch = pytest.importorskip("torch", reason="PyTorch is not installed (Debian: python3-torch)")
    images, background = frames
    tensor = torch.from_numpy(np.ascontiguousarray(images.transpose(0, 3, 1, 2)))
    bg = torch.from_numpy(np.ascontiguousarray(background.transpose(2, 0, 1)))
    for factor in (1, 2, 4):
        got = block_mean(tensor, factor, bg, axes=CHANNELS_FIRST)
        assert isinstance(got, torch.Tensor) and got.dtype == torch.float32
        expected = reference(images, factor, background).transpose(0, 3, 1, 2)
        np.testing.assert_allclose(got.numpy(), expected, rtol=1e-6, atol=1e-6)


def test_refuses_what_has_no_block_mean(frames):
    images, _ = frames
    for factor in (0, -2, 1.5, True, COLS + 1):
        with pytest.raises(ValueError, match="factor|block"):
            block_mean(images, factor)
    with pytest.raises(ValueError, match="one axis twice"):
        block_mean(images, 2, axes=(-2, 2))
    with pytest.raises(ValueError, match="outside"):
        block_mean(images[0], 2, axes=(-4, -2))


def test_norm2tex_block_mean_is_this_function():
    assert norm2tex.block_mean is blocks.block_mean
    assert "block_mean" in dir(norm2tex) and "block_mean" in norm2tex.__all__
