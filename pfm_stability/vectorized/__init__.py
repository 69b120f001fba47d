"""Loop-model verdicts in arrays: millions of parameter points at once.

* `loop_verdicts` (module `vectorized.loops`): every model of
  `parameters.MODEL_NAMES` for arrays of (τ, T, k, NV, c) — the verdict,
  NV*, the gain margin and ω*, equal to what the scalar models of
  `pfm_stability.models` give point by point (docs/models.md);
* `exact_delay_verdicts` (module `vectorized.exact_delay`): the `exact_delay`
  verdict and delay margin for walls and corridors given by KB's power law;
* `vectorized.polynomial`: Routh–Hurwitz (Liénard–Chipart) tests and the
  stable set in the gain K of D + K·E, in arrays over points;
* `vectorized.sampled`: the `sampled` model's polynomials in closed form
  (`vectorized.zoh`: the zero-order hold by φ-functions);
* `vectorized.delay_verdicts`: `exact_delay` verdicts with one crossing
  frequency, for ``loop_verdicts(..., columns="verdict")``.
"""

from .exact_delay import VectorVerdicts, delay_verdicts_from_gain, exact_delay_verdicts, heading_gain_array, loop_gain_arrays, resolved_lag_and_delay
from .loops import LoopVerdicts, loop_verdicts

__all__ = [
    "LoopVerdicts",
    "VectorVerdicts",
    "delay_verdicts_from_gain",
    "exact_delay_verdicts",
    "heading_gain_array",
    "loop_gain_arrays",
    "loop_verdicts",
    "resolved_lag_and_delay",
]
