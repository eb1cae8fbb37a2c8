#!/usr/bin/env python3
"""Drives the Tissue FMU through FMPy (a third-party FMI 3.0 importer) for 30 parallel plus 30
crossing scalpel strokes on the frog with the fine render surface on (surface.renderSurface =
"frog"), and checks after every communication step that the whole surface is delivered: the FMU
never truncates surface.mesh, and with large capacities the arrays hold it all too.

The strokes are the careless cross-hatching of tests/extremes (FrogCrossHatched, 30 + 30 in
docs/BENCHMARKS.md) in FMU terms, on the tail-held frog of host/scenarios/cut_frog_complete.toml
(fixedRegion.axis 0, fraction 0.3, E 3e5 Pa, blade 0.2 m, tip 2 heights below the belly). The frog's
geometry is the bounding box of surface.mesh at rest. A vertical scalpel (orientation identity: the
tool axis +z) first makes --strokes strokes along x (the body's length, through the held tail) at y
spread over the middle two thirds of the width, then --strokes strokes along y (across the body) at
x spread over the middle two thirds of the length, from the head towards the tail (a cut ahead of the
held slab frees what lies ahead of it; head first, each stroke still finds tissue). Between strokes
the tool is put away (mode none) and carried outside the body to the next start; the scalpel is
switched on only once the tool has arrived there (tool.appliedPosition: the FMU holds the tool to
tool.maxSpeed).

Checks after every doStep (a failure makes the exit code 1):
  * surface.mesh decodes ("TSM1", version 1, exactly the size its counts give);
  * surface.vertexCount / surface.triangleCount equal min(V, capacity) / min(T, capacity) of
    surface.mesh (the full V and T with large capacities: that is checked too),
    surface.cutTriangleCount equals its C, and the first rows of surface.vertexPositions /
    surface.triangles equal surface.mesh's exactly (rows after them are 0);
  * surface.embedding ("TSE1") and surface.nodes ("TSN1") decode, carry surface.revision, the same N,
    P = V, the same T, C and triangles as surface.mesh, and the points mapped at the nodes
    (sum_k w_ik node[n_ik]) equal surface.mesh's positions within 1e-12 m;
  * every triangle index < V.
Reported, not failed: border edges of surface.mesh (directed edges whose reverse is absent: open
loops where crossing cuts meet are a known limitation), directed edges used twice, the FMU's log.

Usage (FMPy from its source tree, numpy):
  PYTHONPATH=/work/peers/fmi/src/FMPy/src /usr/bin/python3 tests/bench/fmpy_strokes.py \
      [--fmu build/release/fmus/Tissue.fmu] [--strokes 30] [--default-capacities] [--max-wall S]
"""
import argparse
import ctypes
import pathlib
import shutil
import signal
import struct
import sys
import time

import numpy as np

import fmpy
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave, fmi3ValueReference

from hatch_plan import hatched_strokes

ROOT = pathlib.Path(__file__).resolve().parents[2]

MESH_MAGIC = 0x314D5354       # "TSM1"
EMBEDDING_MAGIC = 0x31455354  # "TSE1"
NODES_MAGIC = 0x314E5354      # "TSN1"
BINARY_VERSION = 1
MAP_TOLERANCE_M = 1e-12

TOOL_NONE, TOOL_PROBE, TOOL_SCALPEL = 0, 1, 2
STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL"]


# ---- The Binary surface outputs (libports/ports/surface_binary.hpp) ------------------------------

class DecodeError(Exception):
    pass


def decode_mesh(buf):
    """surface.mesh: u32 magic | u32 version | u64 V | u64 T | u64 C | f64[3V] | u32[3T]."""
    if buf is None or len(buf) < 32:
        raise DecodeError(f"surface.mesh: {0 if buf is None else len(buf)} bytes, shorter than its header")
    magic, version, v, t, c = struct.unpack_from("<IIQQQ", buf, 0)
    if magic != MESH_MAGIC or version != BINARY_VERSION:
        raise DecodeError(f"surface.mesh: magic {magic:#x} version {version}")
    size = 32 + 24 * v + 12 * t
    if len(buf) != size:
        raise DecodeError(f"surface.mesh: {len(buf)} bytes, its counts (V {v}, T {t}) give {size}")
    if c > t:
        raise DecodeError(f"surface.mesh: C {c} > T {t}")
    positions = np.frombuffer(buf, dtype="<f8", count=3 * v, offset=32).reshape(v, 3)
    triangles = np.frombuffer(buf, dtype="<u4", count=3 * t, offset=32 + 24 * v).reshape(t, 3)
    return positions, triangles, c


def decode_embedding(buf):
    """surface.embedding: u32 magic | u32 version | u64 revision | u64 N | u64 P | u64 T | u64 C |
    u32[4P] nodes | f64[4P] weights | u32[3T] triangles."""
    if buf is None or len(buf) < 48:
        raise DecodeError(f"surface.embedding: {0 if buf is None else len(buf)} bytes, shorter than its header")
    magic, version, revision, n, p, t, c = struct.unpack_from("<IIQQQQQ", buf, 0)
    if magic != EMBEDDING_MAGIC or version != BINARY_VERSION:
        raise DecodeError(f"surface.embedding: magic {magic:#x} version {version}")
    size = 48 + 16 * p + 32 * p + 12 * t
    if len(buf) != size:
        raise DecodeError(f"surface.embedding: {len(buf)} bytes, its counts (P {p}, T {t}) give {size}")
    nodes = np.frombuffer(buf, dtype="<u4", count=4 * p, offset=48).reshape(p, 4)
    weights = np.frombuffer(buf, dtype="<f8", count=4 * p, offset=48 + 16 * p).reshape(p, 4)
    triangles = np.frombuffer(buf, dtype="<u4", count=3 * t, offset=48 + 48 * p).reshape(t, 3)
    return revision, n, nodes, weights, triangles, c


def decode_nodes(buf):
    """surface.nodes: u32 magic | u32 version | u64 revision | u64 N | f64[3N]."""
    if buf is None or len(buf) < 24:
        raise DecodeError(f"surface.nodes: {0 if buf is None else len(buf)} bytes, shorter than its header")
    magic, version, revision, n = struct.unpack_from("<IIQQ", buf, 0)
    if magic != NODES_MAGIC or version != BINARY_VERSION:
        raise DecodeError(f"surface.nodes: magic {magic:#x} version {version}")
    if len(buf) != 24 + 24 * n:
        raise DecodeError(f"surface.nodes: {len(buf)} bytes, N {n} gives {24 + 24 * n}")
    return revision, np.frombuffer(buf, dtype="<f8", count=3 * n, offset=24).reshape(n, 3)


def border_edges(triangles, vertex_count):
    """Directed edges of the triangles without their reverse, and directed edges used more than once."""
    if len(triangles) == 0:
        return 0, 0
    t = triangles.astype(np.int64)
    a = t.ravel()
    b = t[:, [1, 2, 0]].ravel()
    v = np.int64(max(vertex_count, 1))
    keys = a * v + b
    reverse = b * v + a
    border = int(np.count_nonzero(~np.isin(reverse, keys)))
    repeated = int(len(keys) - len(np.unique(keys)))
    return border, repeated


# ---- The FMU ----------------------------------------------------------------------------------------

class Log:
    """The FMU's log messages: counted by status, the first of each kind printed."""

    def __init__(self):
        self.counts = [0] * 6
        self.seen = {}

    def __call__(self, environment, status, category, message):
        status = int(status)
        self.counts[min(status, 5)] += 1
        text = message.decode("utf-8", "replace") if message else ""
        cat = category.decode("utf-8", "replace") if category else ""
        key = (status, cat, text[:60])
        self.seen[key] = self.seen.get(key, 0) + 1
        if status >= 1 and self.seen[key] <= 2:
            label = STATUS[status] if status < len(STATUS) else str(status)
            print(f"  [FMU {label} {cat}] {text}", flush=True)


class Tissue:
    def __init__(self, fmu_path, capacity, log):
        self.md = fmpy.read_model_description(str(fmu_path))
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.unzipdir = fmpy.extract(str(fmu_path))
        self.fmu = FMU3Slave(guid=self.md.instantiationToken, unzipDirectory=self.unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="tissue")
        self.fmu.instantiate(loggingOn=False, logMessage=log)
        if capacity:
            self.set("surface.vertexCapacity", capacity)
            self.set("surface.triangleCapacity", capacity)
        self.vertex_capacity = int(self.get_start("surface.vertexCapacity") if not capacity else capacity)
        self.triangle_capacity = int(self.get_start("surface.triangleCapacity") if not capacity else capacity)
        # Preallocated buffers for the arrays, read through FMPy's ctypes bindings (its list-returning
        # wrappers would build 1.2 million Python numbers a step).
        self.positions = np.zeros((self.vertex_capacity, 3), dtype=np.float64)
        self.triangles = np.zeros((self.triangle_capacity, 3), dtype=np.uint32)
        self.vr = {name: v.valueReference for name, v in self.vars.items()}

    def get_start(self, name):
        return self.vars[name].start

    def set(self, name, value):
        v = self.vars[name]
        values = list(value) if isinstance(value, (list, tuple)) else [value]
        setter = {"Float64": self.fmu.setFloat64, "Int32": self.fmu.setInt32, "Int64": self.fmu.setInt64,
                  "UInt64": self.fmu.setUInt64, "UInt32": self.fmu.setUInt32, "Boolean": self.fmu.setBoolean,
                  "String": self.fmu.setString, "Enumeration": self.fmu.setInt64}[v.type]
        setter([v.valueReference], values)

    def read_arrays(self):
        vr = (fmi3ValueReference * 1)(self.vr["surface.vertexPositions"])
        self.fmu.fmi3GetFloat64(self.fmu.component, vr, 1,
                                self.positions.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), self.positions.size)
        vr = (fmi3ValueReference * 1)(self.vr["surface.triangles"])
        self.fmu.fmi3GetUInt32(self.fmu.component, vr, 1,
                               self.triangles.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32)), self.triangles.size)

    def close(self):
        try:
            self.fmu.terminate()
        except Exception as error:  # noqa: BLE001 - report and go on freeing
            print(f"  terminate: {error}")
        self.fmu.freeInstance()
        shutil.rmtree(self.unzipdir, ignore_errors=True)


# ---- The run --------------------------------------------------------------------------------------

class Run:
    def __init__(self, args):
        self.args = args
        self.log = Log()
        self.large = not args.default_capacities
        self.tissue = Tissue(args.fmu, args.capacity if self.large else 0, self.log)
        self.t = 0.0
        self.steps = 0
        self.failures = []          # (step, message)
        self.failed_steps = 0
        self.fmu_error = None
        self.step_wall = []
        self.check_wall = []
        self.max_v = self.max_t = self.max_c = 0
        self.border_steps = 0
        self.max_border = 0
        self.first_border = None    # (step, t, stroke) of the first step with border edges
        self.max_repeated = 0
        self.truncated_steps = 0
        self.last_tris_bytes = None
        self.last_border = (0, 0)
        self.max_map_error = 0.0
        self.mode = TOOL_NONE
        self.position = [0.0, 0.0, 0.0]
        self.last = {}
        self.stop_reason = None
        self.strokes_done = 0
        self.strokes_that_cut = 0

    # --- setup
    def setup(self):
        a = self.args
        s = self.tissue
        s.set("surface.renderSurface", a.render_surface)
        s.set("tool.bladeLength", a.blade_length)
        s.set("fixedRegion.axis", a.fixed_axis)
        s.set("fixedRegion.fraction", a.fixed_fraction)
        s.set("material.youngModulus", a.young_modulus)
        s.fmu.enterInitializationMode(startTime=0.0)
        s.set("tool.orientation", [1.0, 0.0, 0.0, 0.0])
        s.set("tool.mode", TOOL_NONE)
        s.fmu.exitInitializationMode()
        mesh, _, _ = decode_mesh(s.fmu.getBinary([s.vr["surface.mesh"]])[0])
        self.lo = mesh.min(axis=0)
        self.hi = mesh.max(axis=0)
        self.check()  # the surface at rest
        print(f"surface at rest: V {len(mesh)}, bounding box {np.round(self.lo, 4)} .. {np.round(self.hi, 4)} m; "
              f"capacities {s.vertex_capacity} / {s.triangle_capacity}", flush=True)

    # --- one communication step and its checks
    def fail(self, message):
        self.failures.append((self.steps, message))
        if len(self.failures) <= 20:
            print(f"  FAIL step {self.steps} (t = {self.t:.2f} s): {message}", flush=True)

    def step(self, position, mode):
        s = self.tissue
        s.set("tool.position", list(position))
        s.set("tool.mode", mode)
        started = time.perf_counter()
        try:
            s.fmu.doStep(self.t, self.args.dt)
        except FMICallException as error:
            self.fmu_error = f"doStep at t = {self.t:.3f} s: {error}"
            raise
        self.step_wall.append(time.perf_counter() - started)
        self.t = round(self.t + self.args.dt, 9)
        self.steps += 1
        started = time.perf_counter()
        self.check()
        self.check_wall.append(time.perf_counter() - started)
        if self.args.max_wall and time.perf_counter() - self.started > self.args.max_wall:
            self.stop_reason = f"--max-wall {self.args.max_wall:g} s reached"
            raise TimeoutError

    def check(self):
        s = self.tissue
        fmu = s.fmu
        vc, tc, cc, revision, cut_tets = fmu.getUInt64([s.vr["surface.vertexCount"], s.vr["surface.triangleCount"],
                                                        s.vr["surface.cutTriangleCount"], s.vr["surface.revision"],
                                                        s.vr["cutTets"]])
        applied = fmu.getFloat64([s.vr["tool.appliedPosition"]], 3)
        mesh_bytes, embedding_bytes, nodes_bytes = fmu.getBinary(
            [s.vr["surface.mesh"], s.vr["surface.embedding"], s.vr["surface.nodes"]])
        s.read_arrays()
        self.last = dict(vc=vc, tc=tc, cc=cc, revision=revision, cut_tets=cut_tets, applied=applied,
                         mesh_bytes=len(mesh_bytes or b""), embedding_bytes=len(embedding_bytes or b""),
                         nodes_bytes=len(nodes_bytes or b""))
        before = len(self.failures)
        try:
            positions, triangles, c = decode_mesh(mesh_bytes)
            v, t = len(positions), len(triangles)
            self.last.update(v=v, t=t, c=c)
            self.max_v, self.max_t, self.max_c = max(self.max_v, v), max(self.max_t, t), max(self.max_c, c)
            # The counts and the arrays against the binary.
            want_vc, want_tc = min(v, s.vertex_capacity), min(t, s.triangle_capacity)
            if vc != want_vc or tc != want_tc:
                self.fail(f"counts {vc} / {tc}, surface.mesh V {v} T {t}, capacities "
                          f"{s.vertex_capacity} / {s.triangle_capacity}")
            if self.large and (vc != v or tc != t):
                self.fail(f"the arrays hold {vc} / {tc} rows of V {v} T {t} (capacity {self.args.capacity} too small)")
            if vc < v or tc < t:
                self.truncated_steps += 1
            if cc != c:
                self.fail(f"surface.cutTriangleCount {cc}, surface.mesh C {c}")
            nv, nt = min(vc, v), min(tc, t)
            if not np.array_equal(s.positions[:nv], positions[:nv]):
                rows = np.nonzero(np.any(s.positions[:nv] != positions[:nv], axis=1))[0]
                self.fail(f"surface.vertexPositions differs from surface.mesh in {len(rows)} of {nv} rows "
                          f"(first {rows[0]})")
            if np.any(s.positions[nv:]):
                self.fail("surface.vertexPositions has non-zero rows after surface.vertexCount")
            if not np.array_equal(s.triangles[:nt], triangles[:nt]):
                rows = np.nonzero(np.any(s.triangles[:nt] != triangles[:nt], axis=1))[0]
                self.fail(f"surface.triangles differs from surface.mesh in {len(rows)} of {nt} rows (first {rows[0]})")
            if np.any(s.triangles[nt:]):
                self.fail("surface.triangles has non-zero rows after surface.triangleCount")
            if t and int(triangles.max()) >= v:
                self.fail(f"a triangle index {int(triangles.max())} >= V {v}")
            # The embedding mapped at the nodes.
            e_revision, e_n, e_nodes, e_weights, e_triangles, e_c = decode_embedding(embedding_bytes)
            n_revision, node_positions = decode_nodes(nodes_bytes)
            if e_revision != revision or n_revision != revision:
                self.fail(f"revisions: surface.revision {revision}, embedding {e_revision}, nodes {n_revision}")
            if e_n != len(node_positions):
                self.fail(f"embedding N {e_n}, surface.nodes N {len(node_positions)}")
            if len(e_nodes) != v or len(e_triangles) != t or e_c != c:
                self.fail(f"embedding P {len(e_nodes)} T {len(e_triangles)} C {e_c}, surface.mesh V {v} T {t} C {c}")
            elif not np.array_equal(e_triangles, triangles):
                self.fail("embedding triangles differ from surface.mesh's")
            elif len(e_nodes) and int(e_nodes.max()) >= len(node_positions):
                self.fail(f"an embedding node index {int(e_nodes.max())} >= N {len(node_positions)}")
            elif len(e_nodes):
                mapped = np.einsum("pk,pkd->pd", e_weights, node_positions[e_nodes])
                error = float(np.max(np.abs(mapped - positions)))
                self.max_map_error = max(self.max_map_error, error)
                if not error <= MAP_TOLERANCE_M:
                    self.fail(f"the embedding mapped at the nodes is {error:.3e} m from surface.mesh")
            # Border edges (reported): the triangles change only with the topology.
            tri_bytes = mesh_bytes[32 + 24 * v:]
            if tri_bytes != self.last_tris_bytes:
                self.last_border = border_edges(triangles, v)
                self.last_tris_bytes = tri_bytes
            border, repeated = self.last_border
            self.last.update(border=border, repeated=repeated)
            if border:
                self.border_steps += 1
                if self.first_border is None:
                    self.first_border = (self.steps, self.t, self.strokes_done + 1, border)
            self.max_border = max(self.max_border, border)
            self.max_repeated = max(self.max_repeated, repeated)
        except DecodeError as error:
            self.fail(str(error))
        if len(self.failures) > before:
            self.failed_steps += 1

    # --- the tool
    def go_to(self, target, mode=TOOL_NONE, max_steps=200):
        """Carries the tool to `target` in `mode` until the FMU applied it there (tool.maxSpeed)."""
        for _ in range(max_steps):
            self.step(target, mode)
            if np.max(np.abs(np.array(self.last["applied"]) - np.array(target))) <= 1e-9:
                return
        self.fail(f"the tool did not arrive at {target} in {max_steps} steps")

    def stroke(self, start, end):
        cuts_before = self.last["cut_tets"]
        self.go_to(start, TOOL_NONE)                        # put away, carried outside the body
        self.step(start, TOOL_SCALPEL)                      # the blade on, outside the body
        length = float(np.linalg.norm(np.array(end) - np.array(start)))
        count = max(1, int(np.ceil(length / (self.args.speed * self.args.dt) - 1e-9)))
        for k in range(1, count + 1):
            f = k / count
            self.step([start[i] + (end[i] - start[i]) * f for i in range(3)], TOOL_SCALPEL)
        self.step(end, TOOL_NONE)                           # put away
        if self.last["cut_tets"] > cuts_before:
            self.strokes_that_cut += 1

    def strokes(self):
        a = self.args
        lo, hi = self.lo, self.hi
        ext = hi - lo
        tip_z = lo[2] - a.tip_below * ext[2]
        if tip_z + a.blade_length < hi[2] + ext[2]:
            print(f"  note: the blade reaches z = {tip_z + a.blade_length:.3f} m, the frog's top is {hi[2]:.3f} m")
        plan = hatched_strokes(lo, hi, a.strokes, a.tip_below, a.margin)
        total = len(plan)
        for k, (kind, where, start, end) in enumerate(plan, 1):
            steps_before, wall_before = self.steps, sum(self.step_wall)
            self.stroke(start, end)
            self.strokes_done = k
            ms = 1e3 * (sum(self.step_wall) - wall_before) / max(self.steps - steps_before, 1)
            L = self.last
            print(f"stroke {k} of {total} ({kind}, {where}): elapsed {time.perf_counter() - self.started:.1f} s, "
                  f"steps {self.steps}, {ms:.1f} ms/doStep, V {L['v']} T {L['t']} C {L['c']}, cutTets {L['cut_tets']}, "
                  f"border edges {L['border']}, failures {len(self.failures)}", flush=True)
        for _ in range(a.settle_steps):
            self.step(self.position_away(), TOOL_NONE)

    def position_away(self):
        return [float(self.hi[0] + self.args.margin * (self.hi[0] - self.lo[0])), float(self.lo[1]),
                float(self.lo[2] - self.args.tip_below * (self.hi[2] - self.lo[2]))]

    def run(self):
        self.started = time.perf_counter()
        try:
            self.setup()
            self.strokes()
        except FMICallException as error:
            if self.fmu_error is None:
                self.fmu_error = str(error)
            self.stop_reason = f"FMU call failed: {self.fmu_error}"
        except TimeoutError:
            pass
        except KeyboardInterrupt:
            self.stop_reason = "interrupted"
        total = time.perf_counter() - self.started
        self.summary(total)
        self.tissue.close()
        if self.failures:
            return 1
        if self.fmu_error:
            return 3
        return 0

    def summary(self, total):
        a = self.args
        L = self.last
        step_ms = 1e3 * np.mean(self.step_wall) if self.step_wall else float("nan")
        check_ms = 1e3 * np.mean(self.check_wall) if self.check_wall else float("nan")
        print()
        print("==== summary ====")
        print(f"FMU: {a.fmu}; capacities {self.tissue.vertex_capacity} / {self.tissue.triangle_capacity}"
              f"{' (defaults)' if not self.large else ''}; render surface {a.render_surface!r}; "
              f"speed {a.speed} m/s, communication step {a.dt} s")
        print(f"strokes completed: {self.strokes_done} of {2 * a.strokes} ({self.strokes_that_cut} cut a tet)"
              + (f"; STOPPED: {self.stop_reason}" if self.stop_reason else ""))
        print(f"steps: {self.steps} (t = {self.t:.2f} s)")
        if L:
            print(f"final surface.mesh: V {L.get('v')}, T {L.get('t')}, C {L.get('c')}; arrays "
                  f"{L['vc']} / {L['tc']} rows; revision {L['revision']}; cut tets {L['cut_tets']}")
            print(f"max reached: V {self.max_v}, T {self.max_t}, C {self.max_c}")
            print(f"checks with truncated arrays: {self.truncated_steps} of {self.steps + 1} (the rest state and every step)")
            print(f"border edges: {self.border_steps} of {self.steps + 1} checks had some, max {self.max_border} "
                  f"(final {L.get('border')}); directed edges used twice: max {self.max_repeated}")
            if self.first_border:
                print(f"first border edges: step {self.first_border[0]} (t = {self.first_border[1]:.2f} s, during "
                      f"stroke {self.first_border[2]}): {self.first_border[3]}")
            print(f"max |embedding mapped - surface.mesh|: {self.max_map_error:.3e} m")
            print(f"bytes at the end: surface.mesh {L['mesh_bytes']}, surface.embedding {L['embedding_bytes']}, "
                  f"surface.nodes {L['nodes_bytes']}")
        print(f"wall: mean doStep {step_ms:.2f} ms, mean read + checks {check_ms:.2f} ms per step, total {total:.1f} s")
        print(f"FMU log: {self.log.counts[1]} warnings, {self.log.counts[2]} discards, {self.log.counts[3]} errors, "
              f"{self.log.counts[4]} fatal")
        for (status, cat, text), n in sorted(self.log.seen.items()):
            if status >= 1:
                print(f"  {n} x [{STATUS[status] if status < len(STATUS) else status} {cat}] {text}...")
        if self.fmu_error:
            print(f"FMU ERROR: {self.fmu_error}")
        print(f"delivery checks: {'FAILED' if self.failures else 'passed'} "
              f"({len(self.failures)} failures in {self.failed_steps} steps)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", type=pathlib.Path, default=ROOT / "build/release/fmus/Tissue.fmu")
    parser.add_argument("--strokes", type=int, default=30, help="strokes each way (default 30: 30 + 30)")
    parser.add_argument("--capacity", type=int, default=400000,
                        help="surface.vertexCapacity and surface.triangleCapacity (default 400000)")
    parser.add_argument("--default-capacities", action="store_true",
                        help="leave the capacities at the FMU's defaults (the arrays truncate; surface.mesh must not)")
    parser.add_argument("--render-surface", default="frog")
    parser.add_argument("--speed", type=float, default=0.2, help="stroke speed, m/s")
    parser.add_argument("--dt", type=float, default=0.01, help="communication step, s")
    parser.add_argument("--blade-length", type=float, default=0.2)
    parser.add_argument("--tip-below", type=float, default=2.0,
                        help="the tip this many frog heights below the belly (cut_frog_complete: 2)")
    parser.add_argument("--margin", type=float, default=0.15,
                        help="strokes start and end this fraction of the extent outside the body")
    parser.add_argument("--fixed-axis", type=int, default=0)
    parser.add_argument("--fixed-fraction", type=float, default=0.3)
    parser.add_argument("--young-modulus", type=float, default=3e5)
    parser.add_argument("--settle-steps", type=int, default=10, help="steps after the last stroke")
    parser.add_argument("--max-wall", type=float, default=0.0, help="stop after this many seconds (0: never)")
    args = parser.parse_args()
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    print(f"fmpy {getattr(fmpy, '__version__', '?')} from {pathlib.Path(fmpy.__file__).parent}; FMU {args.fmu}",
          flush=True)
    return Run(args).run()


if __name__ == "__main__":
    sys.exit(main())
