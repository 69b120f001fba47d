"""Judging a lateral motion (docs/maps.md, "Where each part lives"; docs/judge.md): what an oscillation episode is
(`episodes`) and every threshold of that judge (`judge_thresholds`), and the loop driven along a route as the
prediction's motion (`driven`). The map's prediction and the drives' validation
(`validation.map_drives`) are judged by the same rule."""

__all__ = []
