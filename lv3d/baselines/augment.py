"""Seeded data augmentation for the CNN baseline, one call per mini-batch, in plain torch.

Geometric (every channel, so colour and depth stay aligned): random horizontal flip (p = 0.5) and a
random affine map (p = 0.8: rotation within +-10 degrees, translation within +-8 % of the image
side, scale 0.9-1.1), resampled bilinearly with the border pixels extended (the table goes on).
Photometric (the three colour channels only, p = 0.8): brightness, contrast and saturation factors
in [0.8, 1.2] and a hue rotation within +-0.02 turns (in YIQ space).

All draws come from the ``torch.Generator`` passed in, so a seed fixes the augmentation exactly.
Why not kornia: its ColorJitter hue step alone cost ~0.4 s per 16-image batch here (HSV round trip),
more than the network's forward and backward pass together.
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F

# colour channels of the pixel tensors are (x / 255 - 0.5) / 0.25, see lv3d.baselines.pixels
COLOR_MEAN, COLOR_SCALE = 0.5, 0.25
_RGB2YIQ = torch.tensor([[0.299, 0.587, 0.114], [0.596, -0.274, -0.322], [0.211, -0.523, 0.312]])
_YIQ2RGB = torch.linalg.inv(_RGB2YIQ)
_GRAY = torch.tensor([0.299, 0.587, 0.114])


def _uniform(n: int, lo: float, hi: float, gen: torch.Generator) -> torch.Tensor:
    return lo + (hi - lo) * torch.rand(n, generator=gen)


def geometric(x: torch.Tensor, gen: torch.Generator, degrees: float = 10.0, translate: float = 0.08,
              scale: tuple[float, float] = (0.9, 1.1), p_affine: float = 0.8) -> torch.Tensor:
    """(N, C, S, S) -> (N, C, S, S): flip and affine-warp each image with its own random draw."""
    n = x.shape[0]
    flip = torch.rand(n, generator=gen) < 0.5
    x = torch.where(flip[:, None, None, None], x.flip(-1), x)
    angle = _uniform(n, -degrees, degrees, gen) * (math.pi / 180.0)
    s = _uniform(n, *scale, gen)
    shift = _uniform(2 * n, -2.0 * translate, 2.0 * translate, gen).view(n, 2)  # grid coords span 2 per side
    apply = torch.rand(n, generator=gen) < p_affine
    angle, s = torch.where(apply, angle, 0.0), torch.where(apply, s, 1.0)
    shift = torch.where(apply[:, None], shift, 0.0)
    # theta maps output to input coordinates: the inverse of "rotate by angle, scale by s"
    cos, sin = torch.cos(angle) / s, torch.sin(angle) / s
    theta = torch.stack([torch.stack([cos, -sin, shift[:, 0]], 1), torch.stack([sin, cos, shift[:, 1]], 1)], 1)
    grid = F.affine_grid(theta, list(x.shape), align_corners=False)
    return F.grid_sample(x, grid, mode="bilinear", padding_mode="border", align_corners=False)


def color_jitter(rgb: torch.Tensor, gen: torch.Generator, strength: float = 0.2, hue: float = 0.02,
                 p: float = 0.8) -> torch.Tensor:
    """(N, 3, S, S) normalised colour -> the same, jittered per image (see module doc)."""
    n = rgb.shape[0]
    c = (rgb * COLOR_SCALE + COLOR_MEAN).clamp(0.0, 1.0)
    apply = (torch.rand(n, generator=gen) < p).float()
    b = 1.0 + apply * _uniform(n, -strength, strength, gen)
    k = 1.0 + apply * _uniform(n, -strength, strength, gen)
    sat = 1.0 + apply * _uniform(n, -strength, strength, gen)
    turn = apply * _uniform(n, -hue, hue, gen) * (2.0 * math.pi)
    c = (c * b[:, None, None, None]).clamp(0.0, 1.0)
    gray = torch.einsum("c,nchw->nhw", _GRAY, c)[:, None]
    c = (gray.mean(dim=(2, 3), keepdim=True) + k[:, None, None, None] * (c - gray.mean(dim=(2, 3), keepdim=True)))
    c = c.clamp(0.0, 1.0)
    gray = torch.einsum("c,nchw->nhw", _GRAY, c)[:, None]
    c = (gray + sat[:, None, None, None] * (c - gray)).clamp(0.0, 1.0)
    # hue: rotate the chroma plane (I, Q) of YIQ by the drawn angle; one 3x3 matrix per image
    cos, sin = torch.cos(turn), torch.sin(turn)
    one, zero = torch.ones(n), torch.zeros(n)
    rot = torch.stack([torch.stack([one, zero, zero], 1), torch.stack([zero, cos, -sin], 1),
                       torch.stack([zero, sin, cos], 1)], 1)
    m = _YIQ2RGB @ rot @ _RGB2YIQ  # (n, 3, 3)
    c = torch.einsum("nij,njhw->nihw", m, c).clamp(0.0, 1.0)
    return (c - COLOR_MEAN) / COLOR_SCALE


def augment(x: torch.Tensor, gen: torch.Generator, color: bool) -> torch.Tensor:
    """A batch (N, C, S, S) augmented; ``color``: channels 0-2 are colour (rgb and rgbd inputs)."""
    x = geometric(x, gen)
    if color:
        x = torch.cat([color_jitter(x[:, :3], gen), x[:, 3:]], dim=1)
    return x
