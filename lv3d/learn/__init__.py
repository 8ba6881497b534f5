"""Learning shape concepts with the meta-interpretive learner in prolog/ (docs/learner.md).

``fit`` learns one target's program from scenes' facts; ``Model`` holds one program per class and
classifies and explains; ``run_task`` and ``learn_task`` learn a task file (Metagol's example files unchanged,
or lv3d's form)."""

from .engine import LearnError as LearnError
from .model import Explanation as Explanation
from .model import Model as Model
from .model import fit as fit
from .program import Program as Program
from .task import learn_task as learn_task
from .task import run_task as run_task
