"""Statistical baselines trained on exactly the images and folds the learner gets: a small CNN
(rgb, depth, rgbd early fusion, rgbd two-stream), a decision tree on downsampled pixels, and an
ImageNet-pretrained network's features with a linear classifier (rgb, jet-coloured depth, both)."""

from .cnn import CNNClassifier as CNNClassifier
from .cnn import CNNSettings as CNNSettings
from .pixels import frame_tensor as frame_tensor
from .pretrained import PretrainedClassifier as PretrainedClassifier
from .pretrained import PretrainedSettings as PretrainedSettings
from .tree import PixelTree as PixelTree
