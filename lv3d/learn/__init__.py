"""Learning shape concepts with the meta-interpretive learner in prolog/ (docs/learner.md).

``fit`` learns one target's program from scenes' facts; ``Model`` holds one program per class and
classifies and explains; ``learn_task`` runs a Metagol-style task file."""

from .engine import LearnError as LearnError
from .model import Explanation as Explanation
from .model import Model as Model
from .model import fit as fit
from .program import Program as Program
from .task import learn_task as learn_task
