"""norm2tex.rl.hold_images: the images of a held cube, and whether the policies' image network
can tell materials apart from them. Wood's grain is shallow, smooth's relief nearly none: with
texture, the network must name them on held-out variants and seeds; rendered textureless
(beta 0), the two give the same images, and it must not do better than a coin by much.

Run (with the workspace sourced): /usr/bin/python3 -m pytest -q test/python/test_hold_images.py
"""
import numpy as np
import pytest

torch = pytest.importorskip("torch")

from norm2tex.rl import hold_images  # noqa: E402


def test_a_scripted_hold_reaches_its_opening_and_images_show_the_press():
    left, right = hold_images.hold_images("wood", "norm2tex", [0, 1], episodes=3, seed=5)
    assert left.shape == right.shape == (3, 320, 240, 3)
    for images in (left, right):
        # A press: the contact moves pixels by tens of grey levels (diff_float is 1/255 units).
        assert (np.abs(images).reshape(3, -1).max(axis=1) * 255 > 20).all()
    # The same seeds give the same images; texture is what beta 0 removes.
    again, _ = hold_images.hold_images("wood", "norm2tex", [0, 1], episodes=3, seed=5)
    np.testing.assert_array_equal(left, again)
    flat, _ = hold_images.hold_images("wood", "textureless", [0, 1], episodes=3, seed=5)
    # Where the textureless press shows at all (its shading's skirt reaches past the contact).
    contact = np.abs(flat).max(axis=-1) * 255 > 2
    texture = np.abs(left - flat).max(axis=-1)[contact] * 255
    assert contact.sum() > 1000 and texture.mean() > 1.0, (contact.sum(), texture.mean())
    assert (np.abs(left - flat).max(axis=-1)[~contact] * 255).mean() < texture.mean() / 3


def test_texture_separates_wood_from_smooth_and_textureless_does_not():
    study = hold_images.separability_study(
        materials=("wood", "smooth"), downscales=(4,), train_episodes=32, test_episodes=8,
        epochs=60, log=lambda line: None)
    textured = study["conditions"]["norm2tex"][0]
    flat = study["conditions"]["textureless"][0]
    assert textured["image_shape"] == [80, 60]
    assert textured["test_images"] == 16 and textured["chance"] == 0.5
    # 16 held-out holds: 12 or more right is above a coin's 50 % at p < 0.04 (14 here).
    assert textured["accuracy"] >= 0.75, textured
    # Textureless, both materials give the same images for the same seeds: nothing to learn.
    assert flat["accuracy"] <= 0.625, flat
