"""dataset_recorder bags read directly with the rosbag Python API, as a streaming Dataset."""

import bisect

import numpy as np
import torch


def _image_array(msg):
    """numpy array of a sensor_msgs/Image (bgr8, rgb8 -> BGR, mono8, 32FC1)."""
    encodings = {"bgr8": (np.uint8, 3), "rgb8": (np.uint8, 3), "mono8": (np.uint8, 1),
                 "32FC1": (np.float32, 1)}
    if msg.encoding not in encodings:
        raise ValueError(f"image encoding {msg.encoding!r} is not supported; "
                         f"valid: {', '.join(encodings)}")
    dtype, channels = encodings[msg.encoding]
    itemsize = np.dtype(dtype).itemsize
    row_bytes = msg.width * channels * itemsize
    if msg.step < row_bytes or len(msg.data) < msg.step * msg.height:
        raise ValueError(f"truncated image message ({len(msg.data)} bytes for "
                         f"{msg.width} x {msg.height} {msg.encoding})")
    rows = np.frombuffer(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)[:, :row_bytes]
    array = rows.copy().view(dtype).reshape(msg.height, msg.width, channels)
    if msg.encoding == "rgb8":
        array = array[:, :, ::-1]
    return array if channels > 1 else array[:, :, 0]


def _split(topic):
    sensor, _, leaf = topic.strip("/").rpartition("/")
    return sensor, leaf


class BagDataset(torch.utils.data.IterableDataset):
    """Tactile frames straight from dataset_recorder bags (the parts of one recording, in order).

    image: "diff" (image - the recorded <sensor>/background) or "raw".
    classes: class names for the targets (default: the materials found, read in a first pass).
    return_labels: the target is a dict of labels (material, variant, sensor, stamp, episode,
        press, press_depth, in_contact, ...) instead of the class index.
    Each frame is handed out once its image and its contact label are read.
    """

    def __init__(self, bags, image="diff", classes=None, return_labels=False, transform=None):
        import rosbag  # Debian's python3-rosbag; imported here so ExportedDataset needs no ROS

        if image not in ("diff", "raw"):
            raise ValueError(f"image must be diff or raw, not {image!r}")
        self._rosbag = rosbag
        self.bags = list(bags)
        if not self.bags:
            raise ValueError("no bag given")
        for path in self.bags:
            try:
                rosbag.Bag(path).close()
            except Exception as e:  # rosbag raises several types for a non-bag
                raise ValueError(f"{path!r} is not a readable bag: {e}") from e
        self.image, self.return_labels, self.transform = image, return_labels, transform
        if classes is None:
            materials = set()
            for path in self.bags:
                with rosbag.Bag(path) as bag:
                    for _, msg, _ in bag.read_messages(topics=["/episode"]):
                        materials.add(msg.material)
            classes = sorted(materials)
        self.classes = list(classes)
        self.class_to_idx = {c: i for i, c in enumerate(self.classes)}

    def _episodes(self):
        """Every episode label, sorted by stamp (read first: an episode message may be stored
        after frames of its episode)."""
        by_stamp = {}
        for path in self.bags:
            with self._rosbag.Bag(path) as bag:
                for _, msg, _ in bag.read_messages(topics=["/episode"]):
                    by_stamp[msg.header.stamp.to_nsec()] = msg
        stamps = sorted(by_stamp)
        return [by_stamp[s] for s in stamps], stamps

    def __iter__(self):
        episodes, episode_stamps = self._episodes()
        backgrounds = {}
        pending = {}  # (sensor, stamp) -> {"image": ..., "contact": ...}
        for path in self.bags:
            with self._rosbag.Bag(path) as bag:
                for topic, msg, _ in bag.read_messages():
                    sensor, leaf = _split(topic)
                    if leaf == "background":
                        backgrounds[sensor] = _image_array(msg).astype(np.float32)
                    elif leaf in ("image_raw", "contact"):
                        key = (sensor, msg.header.stamp.to_nsec())
                        part = pending.setdefault(key, {})
                        part[leaf] = msg
                        if "image_raw" in part and "contact" in part:
                            del pending[key]
                            yield self._sample(key, part, episodes, episode_stamps, backgrounds)
        for key, part in sorted(pending.items(), key=lambda kv: kv[0][1]):
            if "image_raw" in part:  # a recording cut short: no contact label for it
                yield self._sample(key, part, episodes, episode_stamps, backgrounds)

    def _sample(self, key, part, episodes, episode_stamps, backgrounds):
        sensor, stamp = key
        array = _image_array(part["image_raw"]).astype(np.float32)
        if self.image == "diff":
            if sensor not in backgrounds:
                raise ValueError(f"the bags hold no /{sensor}/background to subtract; "
                                 "use image='raw'")
            array = array - backgrounds[sensor]
        tensor = torch.from_numpy(np.ascontiguousarray(array.transpose(2, 0, 1)))
        if self.transform is not None:
            tensor = self.transform(tensor)
        i = bisect.bisect_right(episode_stamps, stamp) - 1
        episode = episodes[i] if i >= 0 else None
        material = episode.material if episode else "unlabelled"
        if not self.return_labels:
            return tensor, self.class_to_idx[material]
        contact = part.get("contact")
        labels = {"material": material, "sensor": sensor, "stamp": stamp}
        if episode is not None:
            for field in ("variant", "episode", "object", "beta", "seed", "scenario", "shard",
                          "press", "press_depth"):
                labels[field] = getattr(episode, field)
        if contact is not None:
            labels.update(in_contact=int(contact.in_contact), normal_force=contact.normal_force,
                          max_indentation=contact.max_indentation,
                          contact_area=contact.contact_area,
                          # Bags recorded before TactileContact had these read as NaN.
                          twist_moment=getattr(contact, "twist_moment", float("nan")),
                          slip_fraction=getattr(contact, "slip_fraction", float("nan")))
        return tensor, labels
