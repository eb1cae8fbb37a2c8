#!/usr/bin/env python3
"""Issue 41, item 3: where the steps of the 30 + 30 careless strokes go, through `import tissue`.

The strokes of tests/bench/fmpy_strokes.py (hatch_plan.py: the tail-held frog of cut_frog_complete,
E 300 kPa, a vertical scalpel at 0.2 m/s, put away between strokes and carried outside the body to
the next start) on the FMU's defaults (1 ms steps, the real-time solver), in blocks of ten steps as
a 10 ms communication step of the FMU takes them, without the FMU's surface outputs. After each
stroke it prints the mean wall time of a block, the unknowns, the parked rows and the cut tets, and
the medians of the stroke's steps' parts (TissueStepReport, ms), the mean Newton corrections and the
median CG iterations. The box of the strokes is the tets' (fmpy_strokes.py takes the render surface's,
within 0.1 mm of it).

Usage: /usr/bin/python3 tests/bench/module_strokes.py [--strokes 30] [--module DIR] [--save-state PREFIX]
(DIR: where tissue*.so is, default build/release/python; PREFIX: body.save() after every tenth stroke
into PREFIX_K.bin). One thread; 10-11 minutes for 30 + 30 on the 2-core AMD EPYC VM.
"""
import argparse
import os
import statistics
import sys
import time

from hatch_plan import hatched_strokes

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
IDENTITY = (1.0, 0.0, 0.0, 0.0)
BLOCK_STEPS = 10  # a 10 ms communication step of 1 ms steps
SPEED_M_PER_S = 0.2


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--strokes", type=int, default=30)
    parser.add_argument("--module", default=os.path.join(ROOT, "build", "release", "python"))
    parser.add_argument("--save-state", default="")
    args = parser.parse_args()
    sys.path.insert(0, args.module)
    import tissue

    body = tissue.Tissue(mesh="frog", fixed_axis=0, fixed_fraction=0.3, young_modulus_pa=3e5, blade_length_m=0.2)
    rest = body.rest_positions_m
    reports = []

    def block(position, mode):
        body.set_tool([float(v) for v in position], IDENTITY, mode)
        started = time.perf_counter()
        for _ in range(BLOCK_STEPS):
            reports.append(body.step())
        return time.perf_counter() - started

    def arrived(target):
        return max(abs(body.tool["position_m"][i] - target[i]) for i in range(3)) <= 1e-9

    started = time.perf_counter()
    plan = hatched_strokes(rest.min(axis=0), rest.max(axis=0), args.strokes)
    for k, (kind, where, start, end) in enumerate(plan, 1):
        reports.clear()
        walls = []
        for _ in range(200):  # carried to the start, put away (the tool's speed is held to tool.maxSpeed)
            walls.append(block(start, "none"))
            if arrived(start):
                break
        walls.append(block(start, "scalpel"))
        length = sum((end[i] - start[i]) ** 2 for i in range(3)) ** 0.5
        count = max(1, int(-(-length // (SPEED_M_PER_S * BLOCK_STEPS * 1e-3))))
        for n in range(1, count + 1):
            walls.append(block([start[i] + (end[i] - start[i]) * n / count for i in range(3)], "scalpel"))
        walls.append(block(end, "none"))

        def median_ms(key):
            return 1e3 * statistics.median(r[key] for r in reports)

        print(f"stroke {k} of {len(plan)} ({kind}, {where}): {1e3 * statistics.mean(walls):.1f} ms a block; "
              f"unknowns {body.dof_count}, parked rows {body.parked_rows}, cut tets {body.cut_tets}; step medians "
              f"(ms): total {median_ms('total_s'):.2f}, assembly {median_ms('assembly_s'):.2f}, solve "
              f"{median_ms('solve_s'):.2f}, guard {median_ms('guard_s'):.2f}, cut {median_ms('cut_s'):.2f}, positions "
              f"{median_ms('positions_s'):.2f}; Newton corrections "
              f"{statistics.mean(r['newton_iterations'] for r in reports):.2f} "
              f"a step, CG iterations {statistics.median(r['linear_iterations'] for r in reports):g}; "
              f"elapsed {time.perf_counter() - started:.0f} s", flush=True)
        if args.save_state and k % 10 == 0:
            with open(f"{args.save_state}_{k}.bin", "wb") as out:
                out.write(body.save())


if __name__ == "__main__":
    main()
