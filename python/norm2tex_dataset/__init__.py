"""PyTorch datasets of norm2tex tactile recordings.

Two ways in:

* :class:`ExportedDataset` reads what ``norm2tex_export`` wrote (PNG frames and
  ``labels.csv``): random access, fast, what a training loop wants.
* :class:`BagDataset` reads ``dataset_recorder`` bags directly with the rosbag
  Python API (no export step): a streaming ``IterableDataset``.

Both return ``(image, target)``: ``image`` a float32 tensor C x H x W (BGR order,
as the sensor publishes; ``diff`` images are ``image - background`` in grey
levels, the paper's classifier input), ``target`` the class index of the
frame's material in ``dataset.classes``. With ``return_labels=True`` the target
is a dict of every label instead (material, variant, sensor, stamp, episode,
press, press_depth, in_contact, ...).
"""

from .exported import ExportedDataset  # noqa: F401
from .bags import BagDataset  # noqa: F401

__all__ = ["ExportedDataset", "BagDataset"]
