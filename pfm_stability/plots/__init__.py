"""Plots (matplotlib): drawing only. Every function takes a result, ``ax=`` (optional), returns the figure, never calls ``plt.show()``.

Each result that has a picture draws itself with ``.plot()``, which calls its function
here (imported inside the method, so nothing loads matplotlib before a picture is
asked for): `analysis.comparison` (``GainCurves``, ``KBErrorMap``, ``RootLocus``:
``comparison``, ``rlocus``), `analysis.region_panels` (``RegionPanel``,
``RegionPanels``: ``regions``), `analysis.traps.TrapAnalysis` (``traps``),
`maps.analysis.MapAnalysis` (``map``), `sim.results.RunResult` (``trajectory``),
`sweeps.summary.SweepFigureData` (``sweep``), `validation` (``BoundaryValidation``,
``SweepResult``, ``SimulatedBoundary``: ``validation``). ``force`` draws a force
law (the grid's effective law against KB's lumped law). Nothing here imports a
module that computes a result (docs/architecture.md), so any result may import it.
"""

__all__: list[str] = []
