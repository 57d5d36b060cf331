"""``holoradar.theory``: closed-form resolution, window and interface formulas.

Re-exports :mod:`holoradar.analysis.theory`.
"""

from .analysis.theory import *  # noqa: F403
from .analysis.theory import __all__  # noqa: F401
