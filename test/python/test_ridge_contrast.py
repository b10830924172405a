"""scripts/ridge_contrast: the ridged press's contrast curve against what the gel model implies
(pytest; needs the devel space's environment for `import norm2tex`).

With the fixed-depth overlay (conformity off) the ridges' contrast cannot depend on the force:
the face covers the measuring box at every force. With the conformity model the gel follows the
ridges in proportion to p / p* below full contact (Johnson), so with an E* that puts p* above the
lighter presses' pressures the curve rises and the shape at 5 N is far below 1.
"""

import json
import os
import subprocess
import sys
import tempfile

import pytest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "ridge_contrast")


def run_script(*args):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "ridges.json")
        done = subprocess.run([sys.executable, SCRIPT, "--json", out, *args],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        with open(out) as f:
            return json.load(f), done.stdout


def test_the_curve_is_flat_without_conformity_and_rises_with_a_stiff_gel():
    off, table = run_script("--conformity", "off")
    assert "largest difference of the shapes" in table
    assert off["forces_n"][-1] == 11.9 and len(off["contrast"]) == len(off["real_contrast"])
    assert min(off["contrast"]) > 1.0  # the ridges show at all
    assert all(s == pytest.approx(1.0, abs=0.05) for s in off["shape"])

    stiff, _ = run_script("--contact-modulus-mpa", "1.5", "--coating-length-mm", "0")
    at_5n = stiff["shape"][stiff["forces_n"].index(5.0)]
    assert at_5n < 0.6
    assert stiff["contrast"] == sorted(stiff["contrast"])  # grows with the force
    # The real curve's own shape, as the script states it.
    assert stiff["real_shape"][-1] == 1.0 and stiff["real_shape"][0] == pytest.approx(1.2 / 3.8)


def test_the_shipped_gel_follows_the_real_curve_and_a_gel_without_its_coating_does_not():
    # The realism goal: the shape (contrast / contrast at 11.9 N) within 0.1 of the real unit's
    # at every force from 5 to 11.9 N, with the shipped sensor (its coating, 0.23 mm). Without
    # the coating the gel follows the ridges fully from 4 N and the curve is flat.
    shipped, _ = run_script()
    assert shipped["coating_length_mm"] == pytest.approx(0.23)
    assert shipped["largest_shape_difference"] <= 0.1, shipped["shape"]
    assert shipped["contrast"] == sorted(shipped["contrast"])  # grows to the firmest press
    bare, _ = run_script("--coating-length-mm", "0")
    assert bare["largest_shape_difference"] > 0.3, bare["shape"]


@pytest.mark.parametrize("args, message", [
    (["--coating-length-mm", "-0.1"], "coating_length_mm"),
    (["--contact-modulus-mpa", "0"], "contact_modulus_mpa"),
])
def test_out_of_range_gel_options_are_clear_errors(args, message):
    done = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 1 and message in done.stderr and "Traceback" not in done.stderr, \
        done.stderr


def test_bad_dimensions_are_refused():
    done = subprocess.run([sys.executable, SCRIPT, "--pitch-mm", "0"], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 2 and "--pitch-mm must be finite and > 0" in done.stderr
