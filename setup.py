# The Python part of norm2tex (python/norm2tex_dataset), installed by catkin_python_setup().
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["norm2tex_dataset"], package_dir={"": "python"}))
