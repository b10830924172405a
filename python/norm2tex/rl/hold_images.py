"""What the hold-the-cube experiment's image policies can see: whether the DIGIT images of a held
cube tell the materials apart at the resolution the policies get.

A scripted hold (no policy): after the environment's grasp, the opening is driven to `opening`
(0.53, below every material's drop threshold) and held; the last step's images, as the policies
observe them (image="diff_float", both sensors), are kept. The policies' own image network
(hold_cube_experiment.SmallCNN, shared by both sensors, its two feature vectors and a linear
layer) is then trained, supervised, to name the material on episodes of the training variants
and seeds, and tested on episodes of the held-out variants and other seeds. Its held-out
accuracy bounds what a policy's encoder could learn to tell apart from one frame: at chance
(1 / number of materials), nothing in the images separates them; well above it, the
information is there and the policy did not use it.

`textureless` renders beta 0: every material then gives the same images for the same height and
opening (only the friction differs, which a cube at rest does not show), so its accuracy is a
control that must stay near chance.
"""

import numpy as np
import torch
from torch import nn

from norm2tex.blocks import block_mean
from norm2tex.envs import HoldCubeVectorEnv
from norm2tex.rl.hold_cube_experiment import IMAGE_GAIN, MATERIALS, SmallCNN

HOLD_OPENING = 0.53
STEP = 0.005


def hold_images(material, condition, variants, episodes, seed, opening=HOLD_OPENING, steps=24,
                batch=8, threads=0):
    """(left, right): full-resolution diff_float images (episodes, rows, cols, 3) of both sensors
    after a scripted hold at `opening`; episode k has seed `seed + k` and a variant drawn from
    `variants`. Raises RuntimeError when a held cube dropped (the opening is then not a hold)."""
    beta = 0.0 if condition == "textureless" else None
    lefts, rights = [], []
    done = 0
    while done < episodes:
        n = min(batch, episodes - done)
        env = HoldCubeVectorEnv(num_envs=n, material=material, variant=list(variants),
                                beta_mm=beta, image="diff_float", force=False,
                                max_episode_steps=steps + 1, threads=threads)
        try:
            obs, _ = env.reset(seed=seed + done)
            for _ in range(steps):
                now = obs["opening"][:, 0]
                # 2 opens, 0 closes, 1 stays: towards the hold opening, then stay.
                actions = np.where(now < opening - STEP / 2, 2,
                                   np.where(now > opening + STEP / 2, 0, 1))
                obs, _, terminated, _, _ = env.step(actions)
                if terminated.any():
                    raise RuntimeError("%s dropped at opening %.3f: not a hold" %
                                       (material, float(now[np.argmax(terminated)])))
            lefts.append(obs["digit_left"].copy())
            rights.append(obs["digit_right"].copy())
        finally:
            env.close()
        done += n
    return np.concatenate(lefts), np.concatenate(rights)


class _MaterialNet(nn.Module):
    """The policies' image network on both sensors, then a linear layer to the materials."""

    def __init__(self, image_shape, classes):
        super().__init__()
        self.image_net = SmallCNN(image_shape)
        self.head = nn.Linear(2 * 64, classes)

    def forward(self, left, right):
        both = self.image_net(torch.cat([left, right], 0) * IMAGE_GAIN)
        return self.head(torch.cat([both[:left.shape[0]], both[left.shape[0]:]], 1))


def _tensor(images):
    return torch.as_tensor(images).permute(0, 3, 1, 2).contiguous()


def material_separability(images, downscale, epochs=60, seed=0, lr=1e-3, batch=32):
    """images: {"train"|"test": {material: (left, right)}} from hold_images. Trains _MaterialNet
    on the train images shrunk by `downscale` and returns its held-out accuracy, the chance
    level and the confusion matrix (rows: true material, columns: named)."""
    materials = list(images["train"])

    def stack(split):
        left, right, labels = [], [], []
        for k, m in enumerate(materials):
            l, r = images[split][m]
            left.append(block_mean(l, downscale))
            right.append(block_mean(r, downscale))
            labels += [k] * len(l)
        return (_tensor(np.concatenate(left)), _tensor(np.concatenate(right)),
                torch.as_tensor(labels))

    train_l, train_r, train_y = stack("train")
    test_l, test_r, test_y = stack("test")
    torch.manual_seed(seed)
    net = _MaterialNet(train_l.shape[2:] + (3,), len(materials))
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    gen = torch.Generator().manual_seed(seed)
    for _ in range(epochs):
        order = torch.randperm(len(train_y), generator=gen)
        for start in range(0, len(order), batch):
            idx = order[start:start + batch]
            loss = nn.functional.cross_entropy(net(train_l[idx], train_r[idx]), train_y[idx])
            opt.zero_grad()
            loss.backward()
            opt.step()
    net.eval()
    with torch.no_grad():
        named = net(test_l, test_r).argmax(1)
    confusion = np.zeros((len(materials), len(materials)), dtype=int)
    for t, p in zip(test_y.tolist(), named.tolist()):
        confusion[t, p] += 1
    return {"downscale": downscale, "image_shape": list(train_l.shape[2:]),
            "accuracy": float((named == test_y).float().mean()),
            "chance": 1.0 / len(materials), "materials": materials,
            "confusion": confusion.tolist(), "train_images": int(len(train_y)),
            "test_images": int(len(test_y))}


def separability_study(materials=MATERIALS, conditions=("textureless", "norm2tex"),
                       downscales=(4, 1), train_episodes=48, test_episodes=16,
                       train_variants=tuple(range(20)), test_variants=(20, 21, 22, 23),
                       train_seed=0, test_seed=1_000_000, epochs=60, log=print):
    """material_separability for every condition and downscale, each condition's images made
    once: {"conditions": {condition: [result per downscale]}, ...the settings}."""
    out = {"hold_opening": HOLD_OPENING, "train_episodes": train_episodes,
           "test_episodes": test_episodes, "conditions": {}}
    for condition in conditions:
        images = {"train": {}, "test": {}}
        for m in materials:
            images["train"][m] = hold_images(m, condition, train_variants, train_episodes,
                                             train_seed)
            images["test"][m] = hold_images(m, condition, test_variants, test_episodes,
                                            test_seed)
        results = []
        for f in downscales:
            r = material_separability(images, f, epochs=epochs)
            log("%-12s downscale %d (%d x %d): held-out accuracy %.3f (chance %.3f)" %
                (condition, f, r["image_shape"][1], r["image_shape"][0], r["accuracy"],
                 r["chance"]))
            results.append(r)
        out["conditions"][condition] = results
    return out
