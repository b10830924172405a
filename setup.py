# The Python part of norm2tex, installed by catkin_python_setup(): python/norm2tex (the
# bindings' package, joined by catkin's generated norm2tex.msg / norm2tex.srv and the compiled
# norm2tex._core) and python/norm2tex_dataset.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(
    **generate_distutils_setup(
        packages=["norm2tex", "norm2tex.envs", "norm2tex.rl", "norm2tex_dataset"], package_dir={"": "python"}
    )
)
