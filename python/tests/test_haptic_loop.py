"""tissue.HapticLoop, the HapticLoop FMU's renderer from Python: its keywords are the FMU's parameters
with the FMU's defaults (read from the built HapticLoop.fmu's modelDescription.xml) and ranges; the
parameters reach the renderer; and the loop closed with a simulated hand on the frog
(python/examples/haptic_loop_frog.py: the tissue at 100 Hz, the loop at 1 kHz) settles on the hand's
push at the tissue's quasi-static force."""
import importlib.util
import math
import os
import pathlib
import xml.etree.ElementTree as ElementTree
import zipfile

import numpy as np
import pytest

import tissue

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "haptic_loop_frog.py"


def example():
    spec = importlib.util.spec_from_file_location("haptic_loop_frog", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def fmu_parameters():
    """{name: (type, start text)} of the built HapticLoop.fmu's parameters."""
    return {name: (kind, start) for name, (kind, start, _, _) in fmu_variables().items()}


def fmu_variables():
    """{name: (type, start, min, description)} of the built HapticLoop.fmu's parameters."""
    host = os.environ.get("TISSUE_HOST")
    if not host:
        pytest.skip("TISSUE_HOST (the built tissue-host) is not set; ctest sets it")
    fmu = pathlib.Path(host).resolve().parents[1] / "fmus" / "HapticLoop.fmu"
    with zipfile.ZipFile(fmu) as archive:
        root = ElementTree.fromstring(archive.read("modelDescription.xml"))
    return {v.get("name"): (v.tag, v.get("start"), v.get("min"), v.get("description"))
            for v in root.find("ModelVariables") if v.get("causality") == "parameter"}


def test_the_keywords_and_defaults_are_the_fmus_parameters():
    parameters = fmu_parameters()
    names = tissue.HapticLoop.fmu_names
    assert sorted(names.values()) == sorted(parameters)  # every parameter, each once
    assert names["device_max_force_n"] == "device.maxForce"
    assert names["contact_damping_n_s_per_m"] == "contact.damping"
    defaults = tissue.HapticLoop().parameters
    for keyword, name in names.items():
        kind, start = parameters[name]
        if kind == "Boolean":
            assert defaults[keyword] is (start == "true"), keyword
        else:
            assert np.array_equal(np.atleast_1d(defaults[keyword]), [float(s) for s in start.split()]), keyword


def test_the_ranges_are_the_fmus():
    # As tests/fmu/test_fmu_ranges.cpp checks the FMU: each declared min is accepted and the nearest
    # value below it refused; each "must be > 0" of a description refuses 0 and accepts a little above.
    keywords = {name: keyword for keyword, name in tissue.HapticLoop.fmu_names.items()}
    checked = 0
    for name, (kind, start, minimum, description) in fmu_variables().items():
        if kind != "Float64" or " " in start:
            continue
        keyword = keywords[name]
        if minimum is not None:
            bound = float(minimum)
            assert tissue.HapticLoop(**{keyword: bound}).parameters[keyword] == bound
            with pytest.raises(ValueError, match=keyword):
                tissue.HapticLoop(**{keyword: bound - max(1e-12, abs(bound) * 1e-9)})
            checked += 1
        if "must be > 0" in description:
            with pytest.raises(ValueError, match=keyword):
                tissue.HapticLoop(**{keyword: 0.0})
            tissue.HapticLoop(**{keyword: 1e-9})
            checked += 1
    assert checked >= 9


@pytest.mark.parametrize("keyword, value", [
    ("device_max_force_n", 0.0), ("device_max_force_n", math.nan), ("device_max_force_rate_n_per_s", -1.0),
    ("step_size_s", 0.0), ("workspace_scale", -2.0), ("cutting_fracture_toughness_j_per_m2", -1.0),
    ("contact_damping_n_s_per_m", math.inf), ("passivity_min_hand_mass_kg", 0.0),
    ("velocity_filter_cutoff_hz", 0.0), ("workspace_offset_m", (0.0, 0.0)), ("workspace_offset_m", (0, math.nan, 0)),
])
def test_a_value_out_of_range_or_not_finite_is_a_value_error_naming_the_keyword(keyword, value):
    with pytest.raises(ValueError, match=keyword):
        tissue.HapticLoop(**{keyword: value})


@pytest.mark.parametrize("keywords", [
    {"max_force_n": 1.0}, {"passivity_control": 1}, {"device_max_force_n": "3"}, {"device_max_force_n": True},
    {"workspace_offset_m": "abc"},
])
def test_an_unknown_keyword_or_a_value_of_the_wrong_type_is_a_type_error(keywords):
    with pytest.raises(TypeError):
        tissue.HapticLoop(**keywords)
    with pytest.raises(TypeError):
        tissue.HapticLoop(0.001)


def plane(stiffness_n_per_m=500.0):
    """A contact with the plane z = 0 at the origin, tool at x0 = 0 with no force: f = -K_c (x - x0)."""
    return {"active": True, "point_m": (0, 0, 0), "normal": (0, 0, 1), "force_on_tool_n": (0, 0, 0),
            "stiffness_n_per_m": np.diag([0.0, 0.0, stiffness_n_per_m]), "tool_position_m": (0, 0, 0)}


def test_the_parameters_reach_the_renderer():
    # Held 1 mm into a 500 N/m plane, the force settles at 0.5 N; the workspace maps the device
    # (tool = offset + scale x device) and the clamp holds the force to device_max_force_n.
    loop = tissue.HapticLoop(workspace_offset_m=(0.0, 0.0, 0.01), workspace_scale=2.0)
    loop.set_sample(plane())
    for _ in range(50):
        force = loop.tick((0.0, 0.0, -0.0055))
    assert loop.tool_position_m == pytest.approx((0.0, 0.0, -0.001), abs=1e-15)
    assert force == pytest.approx((0.0, 0.0, 0.5), abs=1e-9)
    assert loop.force_n == pytest.approx(force) and loop.samples_received == 1
    assert loop.time_s == pytest.approx(0.05)
    clamped = tissue.HapticLoop(device_max_force_n=0.3)
    clamped.set_sample(plane())
    for _ in range(50):
        force = clamped.tick((0.0, 0.0, -0.001))
    assert force[2] == pytest.approx(0.3) and clamped.force_clamped
    clamped.reset()
    assert not clamped.has_sample and clamped.time_s == 0.0 and clamped.parameters["device_max_force_n"] == 0.3


def test_a_bad_sample_or_tick_is_a_value_error_and_changes_nothing():
    loop = tissue.HapticLoop()
    loop.set_sample(plane())
    bad = dict(plane(), normal=(0.0, 0.0, 2.0))
    with pytest.raises(ValueError, match="normal"):
        loop.set_sample(bad)
    assert loop.samples_received == 1
    with pytest.raises(ValueError):
        loop.tick((0.0, 0.0, 0.0), dt_s=0.0)
    with pytest.raises(ValueError, match="tool mode"):
        loop.tick((0.0, 0.0, 0.0), mode="laser")
    with pytest.raises(TypeError, match="unknown key"):
        loop.set_sample({"force_n": (0, 0, 1)})
    with pytest.raises(TypeError, match="point_m"):
        loop.set_sample(dict(plane(), point_m="here"))
    assert loop.time_s == 0.0


def test_a_hand_pressing_the_frog_settles_at_the_quasi_static_force():
    # The hand (0.2 kg, 3 N s/m, pushed down by 1 N, moving along z) starts 1 mm above the frog's
    # back and falls on it; the tissue steps at 100 Hz, the loop at 1 kHz; 1 s simulated. It rings
    # (depth peaks at 3.5 mm) and settles within 0.6 s.
    ex = example()
    frog, loop, _, record = ex.press(duration_s=1.0)
    force_z = record["force_n"][:, 2]
    speed = np.abs(record["velocity_m_per_s"][:, 2])
    last = record["time_s"] > 0.8
    # Equilibrium: at rest the loop's force balances the push. Over the last 0.2 s the hand moves
    # below 1e-4 m/s, so its damper and inertia account for under 1e-3 N: the force is the push's
    # within that (measured: 1.5e-6 m/s, 1.3e-5 of the fall's 0.12 m/s; the force within 3e-5 N).
    assert speed[last].max() < 1e-4
    assert speed[last].max() < 1e-3 * speed.max()  # the fall's speed decayed a thousandfold
    assert np.abs(force_z[last] - ex.PUSH_N).max() < 1e-3
    assert frog.tool_contact["active"]
    assert loop.observed_energy_j >= 0.0  # the loop absorbed energy from the hand, gave none net
    # The settled force is the tissue's quasi-static force at the point the probe holds: the full
    # model's static equilibrium, gravity included, the contact slid frictionless (as
    # tests/host/test_palpation.cpp checks tissue-host's hand). At rest the loop renders the
    # tissue's sample f0 (x = x0), and the damped tissue at rest is in static equilibrium; what is
    # left is the poke's slide tolerance (1e-3 of the force along the surface) and the tissue's
    # last motion: 1 % (measured: 0.004 % along the normal, 0.009 % the vector; palpation allows 5 %).
    poke = frog.quasi_static_poke(frog.tool_contact["point_m"])
    assert poke["converged"]
    normal = poke["normal"]
    settled = record["force_n"][-1]
    assert settled @ normal == pytest.approx(poke["force_on_tool_n"] @ normal, rel=0.01)
    assert np.linalg.norm(settled - poke["force_on_tool_n"]) < 0.01 * np.linalg.norm(poke["force_on_tool_n"])
