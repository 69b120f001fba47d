"""Deciding a map (docs/maps.md, "Where each part lives"): the lateral equilibria and N along the routes
(`equilibria`), the verdict rule of a sample (`verdicts`, `decide`), the window-edge relay's
cycle (`relay`), the stretches and their one answer (`paths`) with
V* by the same rule (`stretch_speed`), the outputs — CSV, the Nav2 speed mask, its zones by wobble tolerance
(`outputs`, `wobble_zones`) — and Nav2's Regulated Pure Pursuit along the routes with its ZoneParameterFilter mask
(`tracking`, `zone_filter`)."""

__all__ = []
