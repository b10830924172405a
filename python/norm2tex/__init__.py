"""norm2tex from Python: DIGIT tactile images with Norm2Tex texture, without ROS.

The compiled core (``norm2tex._core``) is imported on first use, so that
``from norm2tex.msg import TactileContact`` (catkin's generated messages, which share this
package) costs nothing extra and works where the module was not built.

Units: metres for poses and positions, millimetres where a name ends in ``_mm``, newtons for
forces. Poses are 4x4 homogeneous matrices (numpy float64) or ``(xyz, quaternion_xyzw)`` pairs;
poses returned are 4x4 matrices. Images are numpy arrays of the sensor's size, rows x cols as
its yaml gives them: bgr8 ``(rows, cols, 3) uint8`` as the sensor publishes them, depth
``(rows, cols) float32`` in metres, masks ``(rows, cols) uint8`` ((320, 240) for a DIGIT,
(240, 320) for the GelSight Mini profile, ``config_path("gelsight_mini.yaml")``).

    import norm2tex
    sensor = norm2tex.SensorModel.load(norm2tex.config_path("digit.yaml"))
    renderer = norm2tex.TactileRenderer(sensor)
    ...

Environments for learning (Gymnasium API): ``norm2tex.envs``.
"""

import importlib as _importlib

from norm2tex._paths import config_dir, config_path, material_config, scene_config  # noqa: F401

# What the compiled core exports (help(norm2tex.<name>) for each).
_CORE_NAMES = (
    "Error",
    "SensorModel",
    "TexturedMesh",
    "load_object_mesh",
    "HeightAtlas",
    "bake_normal_map",
    "load_texture",
    "material_names",
    "MaterialConfig",
    "material_texture",
    "RenderedFrame",
    "ShearLoad",
    "read_image",
    "calibrate_sensor",
    "compare_images",
    "measure_ridge_contrast",
    "TactileRenderer",
    "GripperOptions",
    "ObjectOptions",
    "PhysicsOptions",
    "EpisodeOptions",
    "SceneConfig",
    "GripperSim",
    "GelLaw",
    "TactileGripperOptions",
    "TactileGripperBatch",
    "OpeningCommand",
    "SensorMount",
    "HandConfig",
    "HandSimConfig",
    "HandSim",
    "TactileHandOptions",
    "TactileHand",
)

# Python functions exported here, imported on first use like the core's names (name: module).
_PYTHON_NAMES = {"block_mean": "norm2tex.blocks"}

__all__ = (list(_CORE_NAMES) + list(_PYTHON_NAMES)
           + ["config_dir", "config_path", "material_config", "scene_config"])


def __getattr__(name):
    """Imports the compiled core (or a Python module) when one of its names is first asked for
    (PEP 562)."""
    if name in _PYTHON_NAMES:
        return getattr(_importlib.import_module(_PYTHON_NAMES[name]), name)
    if name in _CORE_NAMES or name == "_core":
        try:
            # import_module, not "from norm2tex import _core": that asks this very __getattr__.
            _core = _importlib.import_module("norm2tex._core")
        except ImportError as error:
            raise ImportError(
                "norm2tex's compiled module (norm2tex._core) could not be imported: %s. It is "
                "built with the package when pybind11 is installed (Debian: pybind11-dev); "
                "source the workspace's setup.bash first." % error
            ) from error
        return _core if name == "_core" else getattr(_core, name)
    raise AttributeError("module 'norm2tex' has no attribute %r" % name)


def __dir__():
    return sorted(list(globals().keys()) + list(_CORE_NAMES) + list(_PYTHON_NAMES))
