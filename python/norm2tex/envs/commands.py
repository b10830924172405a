"""The gripper's command modes and the environments' discrete actions: one set of names.

Command modes (a backend's ``step(modes, values)``, ``TactileGripperBatch.step``): ``ABSOLUTE``
and ``DELTA`` have the values of the message ``norm2tex/GripperCommand``'s constants, so a mode
goes into a message as it is; ``KEEP`` (leave the command, send none) comes after them. C++ has
the same values (``norm2tex::OpeningCommand``, bound as ``norm2tex.OpeningCommand``).

The environments' discrete actions (``action="discrete"``, the paper's ``Discrete(3)``) are
``CLOSE``, ``STAY`` and ``OPEN``: a ``DELTA`` of -``DISCRETE_DELTA``, ``KEEP``, a ``DELTA`` of
+``DISCRETE_DELTA``. docs/ros.md, "One table", lists them all.
"""

ABSOLUTE, DELTA, KEEP = 0, 1, 2
MODE_NAMES = {ABSOLUTE: "absolute", DELTA: "delta", KEEP: "keep"}

CLOSE, STAY, OPEN = 0, 1, 2
# How far a discrete CLOSE or OPEN moves the normalised command (the paper's step).
DISCRETE_DELTA = 0.005
