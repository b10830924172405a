"""scripts/texture_contrast against the physics it reports (pytest).

Needs the devel (or install) space's environment: `import norm2tex` must find the compiled
module. A flat face covers the whole imaged gel at every force, so the contact is the same at
2, 5 and 12 N: with the fixed-depth overlay the texture in the image cannot depend on the
force, and with the conformity model it must grow with the pressure until the gel follows all of
the relief (Johnson: p* = pi E* Delta / lambda, times 1 + (2 pi l / lambda)^3 for the coating).
"""

import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import pytest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "texture_contrast")


def run_script(*args):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "contrast.json")
        done = subprocess.run([sys.executable, SCRIPT, "--variants", "1", "--json", out, *args],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        with open(out) as f:
            return json.load(f), done.stdout


def test_conformity_makes_the_texture_grow_with_force_and_the_overlay_does_not():
    on, table = run_script("--materials", "rock,fabric", "--conformity", "on")
    off, _ = run_script("--materials", "rock,fabric", "--conformity", "off")
    assert on["forces_n"] == [2.0, 5.0, 12.0]
    assert "rock" in table and "fabric" in table
    for material in ("rock", "fabric"):
        rms_on = np.array(on["materials"][material]["rms_mean"])
        rms_off = np.array(off["materials"][material]["rms_mean"])
        assert np.all(np.isfinite(rms_on)) and np.all(rms_on > 0.1), (material, rms_on)
        # Fixed depth: the same texture at every force (the face is in contact all over).
        assert np.ptp(rms_off) < 0.02 * rms_off.mean(), (material, rms_off)
        # Conformity: a light press shows less, never more, than a firm one (rock's coarse
        # relief is followed from 2 N, its fine roughness not even at 12 N: below) ...
        assert rms_on[0] < 0.97 * rms_on[2], (material, rms_on)
        assert rms_on[0] <= rms_on[1] * 1.01 and rms_on[1] <= rms_on[2] * 1.01, (material, rms_on)
        # ... and at most what the fixed-depth overlay shows (the full relief).
        assert np.all(rms_on <= rms_off * 1.02), (material, rms_on, rms_off)


def test_the_coating_holds_fine_relief_back_to_a_firm_press():
    # Without the coating (Johnson's half-space) fabric's weave is followed fully from a medium
    # press on; the shipped coating (a plate on the gel: p* times 1 + (2 pi l / lambda)^3) makes
    # the same weave need far more pressure, so it is still growing at a firm one. Coarse relief
    # is held back much less: rock's texture at 12 N keeps more of its bare value than fabric's.
    coated, _ = run_script("--materials", "rock,fabric")
    bare, _ = run_script("--materials", "rock,fabric", "--coating-length-mm", "0")
    assert coated["coating_length_mm"] == pytest.approx(0.23) and bare["coating_length_mm"] == 0
    fabric_bare = np.array(bare["materials"]["fabric"]["rms_mean"])
    fabric_coated = np.array(coated["materials"]["fabric"]["rms_mean"])
    assert fabric_bare[2] == pytest.approx(fabric_bare[1], rel=0.02), fabric_bare
    assert fabric_coated[2] > 1.5 * fabric_coated[1] > 1.5 * fabric_coated[0], fabric_coated
    assert np.all(fabric_coated < fabric_bare), (fabric_coated, fabric_bare)
    kept = {m: coated["materials"][m]["rms_mean"][2] / bare["materials"][m]["rms_mean"][2]
            for m in ("rock", "fabric")}
    assert kept["fabric"] < kept["rock"], kept


def test_the_figure_is_written():
    from PIL import Image

    with tempfile.TemporaryDirectory() as tmp:
        figure = os.path.join(tmp, "forces.png")
        done = subprocess.run([sys.executable, SCRIPT, "--variants", "1", "--materials", "wood",
                               "--forces", "3,9", "--figure", figure],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        width, height = Image.open(figure).size
        assert width > 4 * 240 and height > 320  # 2 forces x (frame, texture), one material


@pytest.mark.parametrize("args, message", [
    (["--materials", "velvet"], "unknown material"),
    (["--forces", "2,-1"], "finite and > 0"),
    (["--forces", "two"], "newtons"),
    (["--variants", "0"], "--variants"),
    (["--coating-length-mm", "3"], "coating_length_mm"),
])
def test_bad_arguments_are_clear_errors(args, message):
    done = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode != 0
    assert message in done.stderr, done.stderr
