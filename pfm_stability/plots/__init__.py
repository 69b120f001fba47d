"""Plots (matplotlib). Every function takes ``ax=`` (optional), returns the figure, never calls ``plt.show()``.

Modules: ``rlocus`` (root locus, critical gain versus k), ``regions`` (stability
regions), ``trajectory`` (simulated runs drawn like KB's figures), ``force``
(grid effective force law against KB's lumped law), ``validation`` (predicted vs
simulated boundaries).
"""

__all__: list[str] = []
