"""Where the package's config files are, from Python (as the C++ tools find them)."""

import os


def config_dir():
    """The package's config/ directory.

    $NORM2TEX_CONFIG_DIR; else share/norm2tex/config of the prefix this package is installed in
    (<prefix>/lib/python3/dist-packages/norm2tex); else the source tree the module was built
    from. Raises FileNotFoundError if none exists.
    """
    env = os.environ.get("NORM2TEX_CONFIG_DIR")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    # <prefix>/lib/python3/dist-packages/norm2tex -> <prefix>/share/norm2tex/config
    prefix = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(here))))
    installed = os.path.join(prefix, "share", "norm2tex", "config")
    if os.path.isdir(installed):
        return installed
    # The source tree: python/norm2tex -> config (devel space and plain-CMake builds run the
    # sources' Python files), or the directory the compiled module was built from.
    source = os.path.join(os.path.dirname(os.path.dirname(here)), "config")
    if os.path.isdir(source):
        return source
    try:
        import importlib

        _core = importlib.import_module("norm2tex._core")
        if os.path.isdir(_core.SOURCE_CONFIG_DIR):
            return _core.SOURCE_CONFIG_DIR
    except ImportError:
        pass
    raise FileNotFoundError("cannot find norm2tex's config directory; set NORM2TEX_CONFIG_DIR")


def config_path(*parts):
    """A file under config/, e.g. config_path("digit.yaml")."""
    return os.path.join(config_dir(), *parts)


def _named(kind, name, what):
    """config/<kind>/<name>.yaml for a name; a path (with '/' or '.yaml') is returned as it is.
    Raises ValueError listing the valid names for an unknown one."""
    if "/" in name or name.endswith(".yaml"):
        return name
    path = config_path(kind, name + ".yaml")
    if not os.path.isfile(path):
        names = sorted(f[:-5] for f in os.listdir(config_path(kind)) if f.endswith(".yaml"))
        raise ValueError("unknown %s '%s'; valid: %s" % (what, name, ", ".join(names)))
    return path


def material_config(material):
    """config/materials/<material>.yaml for a material name (wood, fabric, rock, smooth, print3d);
    a path is returned as it is. Raises ValueError listing the materials for an unknown name."""
    return _named("materials", material, "material")


def scene_config(scene):
    """config/scenes/<scene>.yaml for a scene name (cube, sphere, hold_cube); a path is returned
    as it is. Raises ValueError listing the scenes for an unknown name."""
    return _named("scenes", scene, "scene")
