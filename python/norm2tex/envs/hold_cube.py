"""HoldCubeEnv: the Norm2Tex paper's closed-loop task. Hold a cube with the largest gripper
opening that does not let it fall.

Episode: the simulator grasps the cube (seated at a random height 0-2.5 cm relative to the
DIGITs' centres), then the command is set to a random value in [0.45, 0.55] -- narrower than the
cube: through the scene's compliant drive (1 N/mm) the fingers press with 1.5-3.8 N, a grip that
holds every material -- and held for `grasp_frames` frames. The
policy then changes the opening by -0.005 / 0 / +0.005 per step. Reward per step: the paper's
scaled sigmoid of the opening command (0 at 0.5, 1/2 at 0.6, 1 at 0.7: opening wider is a
lighter grip), 0 and termination when the cube drops; truncated after 128 steps. A texture
variant is drawn per episode from the material's 24.

With empty=True the gripper holds nothing: after the grasp it opens wide until the cube has
fallen to the floor, out of the sensors' reach, then the episode starts as usual (the command in
[0.45, 0.55]) and runs its 128 steps with the same reward and no drop to end it -- what a policy
does with an empty gripper.
"""

import math

import numpy as np

from norm2tex.envs.gripper_env import GripperEnv, GripperVectorEnv
from norm2tex.envs.commands import ABSOLUTE

HORIZON = 128
# empty=True: frames the gripper stays fully open after the grasp, for the cube to fall clear of
# the gels (it falls ~0.2 m to the floor; `dropped` once it is below the gels' lower edge).
EMPTY_DROP_FRAMES = 30
START_OPENING = (0.45, 0.55)
REWARD_LOW, REWARD_MID, REWARD_HIGH = 0.5, 0.6, 0.7
# Steepness of the sigmoid, per unit of opening: 5 / 0.1, so that the unscaled curve has
# reached 0.7 % / 99.3 % at the ends; the scaling then makes them exactly 0 and 1.
REWARD_STEEPNESS = 50.0


def _sigmoid(x):
    return 1.0 / (1.0 + math.exp(-x))


def hold_reward(opening):
    """The paper's reward of a normalised opening: a sigmoid centred on 0.6, scaled so that it is
    0 at (and below) 0.5 and 1 at (and above) 0.7."""
    lo = _sigmoid(REWARD_STEEPNESS * (REWARD_LOW - REWARD_MID))
    hi = _sigmoid(REWARD_STEEPNESS * (REWARD_HIGH - REWARD_MID))
    r = (_sigmoid(REWARD_STEEPNESS * (float(opening) - REWARD_MID)) - lo) / (hi - lo)
    return min(max(r, 0.0), 1.0)


class HoldCubeVectorEnv(GripperVectorEnv):
    """N HoldCubeEnvs stepped together (see GripperVectorEnv). empty=True: no object in the
    gripper (the cube is dropped before each episode starts; no termination)."""

    def __init__(self, num_envs=1, material="wood", variant=None, scene="hold_cube",
                 max_episode_steps=HORIZON, grasp_frames=15, empty=False, **kwargs):
        self.grasp_frames = int(grasp_frames)
        self.empty = bool(empty)
        super().__init__(num_envs=num_envs, material=material, variant=variant, scene=scene,
                         max_episode_steps=max_episode_steps, **kwargs)

    def _after_reset(self, i, rng):
        if self.empty:
            self.backend.step_one(i, ABSOLUTE, 1.0, EMPTY_DROP_FRAMES)
            if not self.backend.state()["dropped"][i]:
                raise RuntimeError("empty gripper: the cube was still held after %d frames fully "
                                   "open" % EMPTY_DROP_FRAMES)
        return (ABSOLUTE, float(rng.uniform(*START_OPENING)), self.grasp_frames)

    def _terminated(self, state, i):
        return False if self.empty else super()._terminated(state, i)

    def _reward(self, state, i):
        return hold_reward(state["commanded_opening"][i])


class HoldCubeEnv(GripperEnv):
    """The paper's task, one environment: HoldCubeEnv() is wood, both sensors, full-resolution
    raw images, discrete actions, in-process. Every GripperEnv parameter applies."""

    _vector_class = HoldCubeVectorEnv

    def __init__(self, **kwargs):
        super().__init__(**kwargs)


def drop_threshold(material="wood", scene="hold_cube", openings=None, hold_frames=60,
                   height_offsets=(0.0, 0.0125, 0.025), **kwargs):
    """The largest opening command at which the cube is still held, found with the physics
    alone (images are rendered but not used): for each opening (ascending), grasp as
    HoldCubeEnv does (from the lowest start command), command the opening, wait hold_frames
    frames; the threshold is the last opening before the first that drops the cube at any of
    the height offsets. The default openings run from the lowest start command (0.45) to 0.7
    in steps of 0.0025 (half a discrete action). Returns (threshold, {opening: dropped at any
    offset}); threshold None when the first opening drops already."""
    if openings is None:
        openings = np.round(np.arange(START_OPENING[0], 0.70001, 0.0025), 4)
    env = HoldCubeVectorEnv(num_envs=len(height_offsets), material=material, variant=0,
                            scene=scene, noise=False, max_episode_steps=None, **kwargs)
    results = {}
    threshold = None
    try:
        for opening in openings:
            dropped = False
            for i, h in enumerate(height_offsets):
                env._start(i, seed=0, options={"height_offset_m": h, "variant": 0})
                env.backend.step_one(i, ABSOLUTE, float(START_OPENING[0]), env.grasp_frames)
            env.backend.step([ABSOLUTE] * env.num_envs, [float(opening)] * env.num_envs,
                             hold_frames)
            dropped = bool(np.any(env.backend.state()["dropped"]))
            results[float(opening)] = dropped
            if dropped:
                break
            threshold = float(opening)
    finally:
        env.close()
    return threshold, results
