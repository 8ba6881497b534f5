"""Statistical baselines trained on exactly the images and folds the learner gets: a small CNN
(rgb, depth, rgbd early fusion, rgbd two-stream) and a decision tree on downsampled pixels."""

from .cnn import CNNClassifier as CNNClassifier
from .cnn import CNNSettings as CNNSettings
from .pixels import frame_tensor as frame_tensor
from .tree import PixelTree as PixelTree
