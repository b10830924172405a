"""The layout norm2tex_export writes, as a map-style torch Dataset."""

import csv
import os

import numpy as np
import torch
from PIL import Image

_NUMERIC = {
    "variant": int, "stamp": int, "episode": int, "beta": float, "seed": int, "shard": int,
    "press": int, "press_depth": float, "in_contact": int, "normal_force": float,
    "max_indentation": float, "contact_area": float, "twist_moment": float,
    "slip_fraction": float,
}


def _parse(kind, text):
    """A label from its CSV text. Integers are read as integers: through a float, a 64-bit seed or
    a nanosecond stamp (above 2**53) would lose its last digits."""
    if kind is int:
        try:
            return int(text)
        except ValueError:
            return int(float(text))  # written as "3.0" or "1e3"
    return kind(text)


def _read_png(path):
    """H x W x C (or H x W) numpy array of a PNG, keeping its bit depth."""
    with Image.open(path) as image:
        array = np.array(image)
    if array.ndim == 3:
        array = array[:, :, ::-1]  # PIL gives RGB; the sensor's images are BGR
    return array


class ExportedDataset(torch.utils.data.Dataset):
    """Frames exported by norm2tex_export.

    root: the export directory (with labels.csv).
    image: "diff" (image - background, float grey levels, 0 where nothing touches),
        "raw" (the sensor image, 0..255), "depth" (gel indentation in millimetres) or "shear"
        (the gel surface's lateral displacement at each pixel, (2, rows, cols), millimetres, gel
        frame x and y; recorded with the recorder's ~record_shear).
    materials, variants, sensors: keep only these (None: all). Holding variants out
        is how the paper tests generalisation to unseen textures.
    transform: applied to the image tensor.
    return_labels: the target is a dict of every label instead of the class index.
    """

    def __init__(self, root, image="diff", materials=None, variants=None, sensors=None,
                 transform=None, return_labels=False):
        if image not in ("diff", "raw", "depth", "shear"):
            raise ValueError(f"image must be diff, raw, depth or shear, not {image!r}")
        labels = os.path.join(root, "labels.csv")
        if not os.path.isfile(labels):
            raise FileNotFoundError(f"{labels} not found: is {root!r} a norm2tex_export directory?")
        self.root, self.image, self.transform = root, image, transform
        self.return_labels = return_labels
        with open(labels, newline="") as f:
            rows = list(csv.DictReader(f))
        for row in rows:
            for key, kind in _NUMERIC.items():
                if key in row and row[key] not in ("", "nan"):
                    row[key] = _parse(kind, row[key])
        self.rows = [r for r in rows
                     if (materials is None or r["material"] in materials)
                     and (variants is None or r["variant"] in variants)
                     and (sensors is None or r["sensor"] in sensors)]
        if image == "depth" and any(not r["depth"] for r in self.rows):
            raise ValueError("image='depth' but some frames were exported without depth")
        if image == "shear" and any(not r.get("shear") for r in self.rows):
            raise ValueError("image='shear' but some frames were exported without the shear field "
                             "(record with dataset_recorder's ~record_shear)")
        self.classes = sorted({r["material"] for r in rows})
        self.class_to_idx = {c: i for i, c in enumerate(self.classes)}

    def __len__(self):
        return len(self.rows)

    def __getitem__(self, index):
        row = self.rows[index]
        path = os.path.join(self.root, row[self.image])
        if self.image == "depth":
            if path.endswith(".tiff"):
                with Image.open(path) as tiff:
                    array = np.array(tiff, dtype=np.float32) * 1000.0  # metres -> mm
            else:
                array = _read_png(path).astype(np.float32) / 1000.0  # micrometres -> mm
            tensor = torch.from_numpy(array)[None]
        elif self.image == "shear":
            array = np.load(path) * np.float32(1000.0)  # (rows, cols, 2) metres -> mm
            tensor = torch.from_numpy(np.ascontiguousarray(array.transpose(2, 0, 1)))
        else:
            array = _read_png(path).astype(np.float32)
            if self.image == "diff":
                array -= 128.0  # stored as image - background + 128
            tensor = torch.from_numpy(np.ascontiguousarray(array.transpose(2, 0, 1)))
        if self.transform is not None:
            tensor = self.transform(tensor)
        if self.return_labels:
            return tensor, dict(row)
        return tensor, self.class_to_idx[row["material"]]
