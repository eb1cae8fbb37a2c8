"""The 30 + 30 careless strokes of issue 41 in tool positions, shared by tests/bench/fmpy_strokes.py
(through the Tissue FMU) and tests/bench/module_strokes.py (through `import tissue`): a vertical
scalpel first makes `strokes` strokes along x (the body's length, through the held tail) at y spread
over the middle two thirds of the width, then `strokes` across (along y) at x spread over the middle
two thirds of the length, head first. Each stroke starts and ends `margin` of the extent outside the
body, the blade's tip `tip_below` body heights below its bottom."""


def hatched_strokes(lo, hi, strokes, tip_below=2.0, margin=0.15):
    """[(kind, where, start, end)] for the body's box [lo, hi] (m); start and end are [x, y, z]."""
    ext = [hi[i] - lo[i] for i in range(3)]
    tip_z = lo[2] - tip_below * ext[2]
    plan = []
    for k in range(strokes):
        y = lo[1] + ext[1] * (1 / 6 + (2 / 3) * k / max(strokes - 1, 1)) + 1.3e-5
        plan.append(("along x", f"y = {y:+.4f}", [lo[0] - margin * ext[0], y, tip_z],
                     [hi[0] + margin * ext[0], y, tip_z]))
    for k in range(strokes):
        x = hi[0] - ext[0] * (1 / 6 + (2 / 3) * k / max(strokes - 1, 1)) + 1.3e-5
        plan.append(("across", f"x = {x:+.4f}", [x, lo[1] - margin * ext[1], tip_z],
                     [x, hi[1] + margin * ext[1], tip_z]))
    return plan
