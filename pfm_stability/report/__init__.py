"""The stability report: verdicts, margins, remedies and KB's error for every robot family and law.

Nothing is imported here: import the module you need (``from pfm_stability.report.X import Y``),
so that importing one module does not load its siblings."""

__all__ = []
