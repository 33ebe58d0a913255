"""Texel: multi-scale virtual haptic textures, from Python.

A thin binding of the C++ engine (libtexel): every function calls the same
library code as the ``texel`` command, so arrays equal the CLI's output byte
for byte. Units are in the keyword names (``central_pitch_db``,
``texel_length_mm``, ``speed_mm_s``); arrays are numpy arrays that own the
engine's buffers (no copy).

    >>> import texel
    >>> m = texel.render(central_pitch_db=10, irregularity_db=-5,
    ...                  texel_length_mm=0.25, seed=7, device="tpad")
    >>> m.dtype, m.shape
    (dtype('uint16'), (19200,))

Areas: rendering (render, reference, document, Document), signals
(load_signal: files and arrays by one rule), the codec (encode, decode,
parse_bitstream), spectra (magnitude_spectrum, analyse_spectrum), the player
(simulate_swipe, render_trace, swipe), the step-wise procedures (Staircase,
GuidedOptimizer, BayesOptimizer), simulated observers (PsychometricObserver,
Matcher, Rater), session databases (Store, read_trials) and running a
protocol's sessions (texel.experiment.Session). Engine errors raise
texel.Error subclasses (InvalidArgument is also a ValueError, IoError also an
OSError) with the engine's message.
"""

from . import _texel
from ._texel import *  # noqa: F401,F403  (the extension's public names)
from . import _front

__version__ = _texel.__version__

__all__ = sorted(name for name in dir(_texel) if not name.startswith("_") and name != "experiment")

# Python-level fronts of the extension's names: real signatures (from the
# stub, __init__.pyi) and reprs. Functions become Python functions calling
# the extension; classes stay the extension's, their methods wrapped.
globals().update(_front.apply(_texel, __name__, _front.pathlib.Path(__file__).with_name("__init__.pyi"), _front.REPRS))

# The package's module, not the extension's submodule the star import brought.
from . import experiment  # noqa: E402

