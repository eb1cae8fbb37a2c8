"""The Python module `tissue` as a user scripts it: a probe press gives the force the C++ tests
assert (springs in series with the effective contact stiffness), a scalpel stroke cuts the frog
and opens its surface, a saved state restored continues bitwise, and bad input is refused with the
core's message."""
import math

import numpy as np
import pytest

import tissue


def clamped_block():
    # tests/unit/tissue/test_tissue.cpp's clamped_block(): 4 x 4 x 2 cubes of 1 cm, held at z = 0.
    return tissue.Tissue(box=(4, 4, 2), box_edge_m=0.01, fixed_axis=2, fixed_fraction=0.0,
                         gravity_m_per_s2=(0.0, 0.0, 0.0), damping_alpha_per_s=20.0, damping_beta_s=0.0,
                         linear_solver="cholmod", step_size_s=0.01)


def test_a_held_press_settles_at_springs_in_series():
    # The C++ test Tissue.ProbeTouchesPushesBackAndLetsGo: pressed 0.1 mm and held, the force along
    # the normal is d / (1/k_n + 1/k), k_n the contact stiffness's frictionless normal stiffness and
    # k the contact spring's, within 2 %; the tangential force below 5 % of it; K_c symmetric
    # positive definite.
    t = clamped_block()
    above = (0.0213, 0.0187, 0.025)
    t.set_tool(above, mode="probe")
    t.step()
    assert not t.contact["active"]
    depth_m = 1e-4
    t.set_tool((above[0], above[1], 0.02 - depth_m), mode="probe")
    t.step(300)
    contact = t.contact
    assert contact["active"]
    force = contact["force_on_tool_n"]
    k_c = contact["stiffness_n_per_m"]
    assert force.shape == (3,) and k_c.shape == (3, 3)
    assert force[2] > 0.0
    assert np.linalg.norm(force[:2]) < 0.05 * force[2]
    assert np.all(np.linalg.eigvalsh(k_c) > 0.0)
    assert np.linalg.norm(k_c - k_c.T) < 1e-9 * np.linalg.norm(k_c)
    k_n = 1.0 / np.linalg.inv(k_c)[2, 2]
    k = t.contact_spring_stiffness_n_per_m
    expected = depth_m / (1.0 / k_n + 1.0 / k)
    assert force[2] == pytest.approx(expected, rel=0.02)
    t.set_tool(above, mode="probe")
    t.step()
    assert not t.contact["active"]


def test_a_scalpel_stroke_cuts_the_frog_and_opens_its_surface():
    t = tissue.Tissue(mesh="frog", gravity_m_per_s2=(0.0, 0.0, 0.0), step_size_s=0.01, blade_length_m=0.1,
                      fixed_axis=0, fixed_fraction=0.01)
    rest = t.rest_positions_m
    lower, upper = rest.min(axis=0), rest.max(axis=0)
    points_before, triangles_before = t.surface()
    assert points_before.shape[1] == 3 and triangles_before.shape[1] == 3
    assert triangles_before.max() < len(points_before)
    x = 0.5 * (lower[0] + upper[0])
    enriching = relayouts = 0
    for n in range(41):  # a vertical blade drawn across the body, 40 steps of 10 ms
        y = lower[1] - 0.01 + n / 40 * (upper[1] - lower[1] + 0.02)
        t.set_tool((x, y, lower[2] - 0.01), mode="scalpel")
        report = t.step()
        # The step's parts are timed inside its total; unknowns come only with newly cut tets.
        parts = ("assembly_s", "solve_s", "guard_s", "cut_s", "enrich_s", "contact_s", "positions_s")
        assert all(report[k] >= 0.0 for k in parts)
        assert sum(report[k] for k in parts) <= report["total_s"] * (1 + 1e-9)
        assert report["new_enriched_dofs"] == 0 or report["newly_cut_tets"] > 0
        enriching += report["new_enriched_dofs"] > 0
        relayouts += report["matrix_relayout"]
    # A cut that must re-lay the tangent out makes room around it for the next steps' (CUT_ROOM_RINGS):
    # the stroke re-lays it out at a few of its cutting steps, not at every one (15 of 16 before).
    assert enriching > 8 and 4 * relayouts <= enriching
    assert t.cut_tets > 50
    assert t.enriched_vertices > 0
    ids = t.cut_tet_ids
    assert len(ids) == t.cut_tets and np.all(np.diff(ids) > 0) and ids.max() < t.tet_count
    # The cut tets straddle the blade's plane x = const at rest.
    faces = t.cut_faces()
    assert len(faces) > 0 and faces.shape[1] == 3
    assert t.dof_count > 3 * (t.vertex_count - 0)  # enriched unknowns on top of the vertices'
    points, triangles = t.surface()
    assert len(triangles) > len(triangles_before)  # the cut faces are drawn
    assert triangles.max() < len(points)
    assert np.all(np.isfinite(points))


def test_the_render_surface_is_cut_with_the_tets():
    t = tissue.Tissue(mesh="frog", gravity_m_per_s2=(0.0, 0.0, 0.0), step_size_s=0.01, blade_length_m=0.1,
                      render_surface="frog")
    before = t.render_surface()
    assert before["triangles"].shape == (23240, 3)  # meshes/frog_surface.obj
    assert before["cap_triangles"] == 0
    assert np.allclose(np.linalg.norm(before["normals"], axis=1), 1.0)
    rest = t.rest_positions_m
    lower, upper = rest.min(axis=0), rest.max(axis=0)
    x = 0.5 * (lower[0] + upper[0])
    for n in range(41):
        y = lower[1] - 0.01 + n / 40 * (upper[1] - lower[1] + 0.02)
        t.set_tool((x, y, lower[2] - 0.01), mode="scalpel")
        t.step()
    after = t.render_surface()
    assert after["cap_triangles"] > 0  # the opening is capped
    assert len(after["triangles"]) > len(before["triangles"])
    assert after["triangles"].max() < len(after["positions_m"])
    assert np.all(np.isfinite(after["positions_m"]))
    assert tissue.Tissue(box=(2, 2, 2)).render_surface() is None


def test_a_restored_state_continues_bitwise():
    t = tissue.Tissue(mesh="frog", step_size_s=0.01)
    top = t.rest_positions_m[:, 2].max()
    centre = t.rest_positions_m.mean(axis=0)
    t.set_tool((centre[0], centre[1], top + 0.002), mode="probe")
    t.step(5)
    t.set_tool((centre[0], centre[1], top - 0.003), mode="probe")
    t.step(5)
    state = t.save()
    assert isinstance(state, bytes) and len(state) > 0
    t.step(10)
    expected = t.positions_m
    expected_force = t.contact["force_on_tool_n"]

    fresh = tissue.Tissue(mesh="frog", step_size_s=0.01)
    fresh.restore(state)
    fresh.set_tool((centre[0], centre[1], top - 0.003), mode="probe")
    fresh.step(10)
    assert fresh.time_s == t.time_s
    assert np.array_equal(fresh.positions_m, expected)
    assert np.array_equal(fresh.contact["force_on_tool_n"], expected_force)

    # A state of another model is refused and changes nothing.
    other = tissue.Tissue(mesh="frog", step_size_s=0.005)
    before = other.positions_m
    with pytest.raises(RuntimeError, match="another model|fingerprint|model"):
        other.restore(state)
    assert np.array_equal(other.positions_m, before)
    with pytest.raises(RuntimeError):
        fresh.restore(b"not a state")


def test_bad_input_is_refused_with_the_cores_message():
    with pytest.raises(ValueError, match=r"poisson_ratio: material.poissonRatio must be finite and in \[0, 0.5\)"):
        tissue.Tissue(box=(2, 2, 2), poisson_ratio=0.5)
    with pytest.raises(TypeError, match="young_modulus"):
        tissue.Tissue(box=(2, 2, 2), young_modulus=1e5)  # the keyword is young_modulus_pa
    with pytest.raises(TypeError, match="pcg_max_iterations must be an integer, got float"):
        tissue.Tissue(box=(2, 2, 2), pcg_max_iterations=2.5)
    # A wrong type names the type the setting takes (an enumeration: its items).
    with pytest.raises(TypeError, match="young_modulus_pa must be a number, got str"):
        tissue.Tissue(box=(2, 2, 2), young_modulus_pa="1e5")
    with pytest.raises(TypeError, match="linearize_at_predicted_end must be a boolean, got float"):
        tissue.Tissue(box=(2, 2, 2), linearize_at_predicted_end=1.0)
    with pytest.raises(TypeError, match=r"linear_solver must be .*pcgTwoLevel.*, got int"):
        tissue.Tissue(box=(2, 2, 2), linear_solver=3)
    with pytest.raises(TypeError):
        tissue.Tissue("frog")  # keywords only
    with pytest.raises(ValueError):
        tissue.Tissue(box=(2, 2, 2), step_size_s=-1.0)
    with pytest.raises(ValueError, match="linear solver|solver"):
        tissue.Tissue(box=(2, 2, 2), linear_solver="lu")
    with pytest.raises(Exception, match="nonexistent"):
        tissue.Tissue(mesh="/nonexistent/mesh.veg")
    with pytest.raises(Exception, match="nonexistent"):
        tissue.Tissue(box=(2, 2, 2), render_surface="/nonexistent/surface.obj")
    t = tissue.Tissue(box=(2, 2, 2), fixed_fraction=0.0)
    with pytest.raises(ValueError):
        t.set_tool((math.nan, 0.0, 0.0))
    with pytest.raises(ValueError, match="knife"):
        t.set_tool((0.0, 0.0, 0.0), mode="knife")
    with pytest.raises(ValueError):
        t.step(0)
    t.step()  # still usable
    assert t.time_s > 0.0


def test_regions_take_their_materials_by_name_and_mistakes_are_refused(tmp_path):
    # Two tets sharing a face, one per region (Vega *SET / *MATERIAL / *REGION): the file's material,
    # then one set by name; a region the mesh does not have and an unknown key are refused.
    mesh = tmp_path / "two.veg"
    mesh.write_text("*VERTICES\n5 3 0 0\n1 0 0 0\n2 0.01 0 0\n3 0 0.01 0\n4 0 0 0.01\n5 0.01 0.01 0.01\n"
                    "*ELEMENTS\nTET\n2 4 0\n1 1 2 3 4\n2 2 5 3 4\n"
                    "*MATERIAL soft\nENU, 1000, 1e5, 0.4\n*MATERIAL stiff\nENU, 1100, 1e6, 0.45\n"
                    "*SET skin\n1\n*SET tumour\n2\n*REGION\nskin, soft\ntumour, stiff\n")
    from_file = tissue.Tissue(mesh=str(mesh), fixed_vertices=[0, 1, 2])
    assert from_file.regions == {"skin": [1e5, 0.4, 1000.0, 1.0], "tumour": [1e6, 0.45, 1100.0, 1.0]}
    set_by_name = tissue.Tissue(mesh=str(mesh), fixed_vertices=[0, 1, 2], damping_alpha_per_s=2.0,
                                regions={"tumour": {"young_modulus_pa": 3e6, "damping_alpha_per_s": 7.0}})
    # A key left out keeps the body's value (poisson_ratio 0.4, density 1000), not the file's; the
    # region without its own alpha takes the body's.
    assert set_by_name.regions["tumour"] == [3e6, 0.4, 1000.0, 7.0]
    assert set_by_name.regions["skin"] == [1e5, 0.4, 1000.0, 2.0]
    with pytest.raises(ValueError, match='"liver", which the mesh does not have'):
        tissue.Tissue(mesh=str(mesh), fixed_vertices=[0, 1, 2], regions={"liver": {"density_kg_per_m3": 1.0}})
    with pytest.raises(ValueError, match="unknown key"):
        tissue.Tissue(mesh=str(mesh), fixed_vertices=[0, 1, 2], regions={"tumour": {"stiffness": 1.0}})
    with pytest.raises(ValueError, match='"tumour".*alpha'):
        tissue.Tissue(mesh=str(mesh), fixed_vertices=[0, 1, 2], regions={"tumour": {"damping_alpha_per_s": -1.0}})


def test_the_material_model_is_chosen_by_name_and_agrees_with_corotational_at_small_strain():
    # A cantilever of 8 x 2 x 2 cubes of 5 mm (E = 1 MPa) sagging under gravity: its tip drops 0.25 mm,
    # strains below 1e-3, where stable Neo-Hookean is linear elasticity to first order, so the sags
    # differ by the strain's order at most, 0.1 % (measured 1.5e-6); an unknown model is refused
    # naming both.
    def settled_tip_sag_m(model):
        t = tissue.Tissue(box=(8, 2, 2), box_edge_m=0.005, fixed_axis=0, fixed_fraction=0.0,
                          young_modulus_pa=1e6, material_model=model, damping_alpha_per_s=30.0,
                          damping_beta_s=0.0, linear_solver="cholmod", step_size_s=0.01, contact=False,
                          cutting=False)
        t.step(150)
        assert t.kinetic_energy_j < 1e-12
        return -(t.positions_m - t.rest_positions_m)[:, 2].min()

    corotational = settled_tip_sag_m("corotationalLinear")
    neo_hookean = settled_tip_sag_m("stableNeoHookean")
    assert 1e-4 < corotational < 1e-3
    assert neo_hookean == pytest.approx(corotational, rel=1e-3)
    assert neo_hookean != corotational  # a different model, not the default again
    with pytest.raises(ValueError, match="material.model must be corotationalLinear or stableNeoHookean"):
        tissue.Tissue(box=(2, 2, 2), material_model="neoHookean")


def test_the_keywords_are_the_settings_schemas_with_the_fmus_defaults():
    doc = tissue.Tissue.__init__.__doc__
    # Every Tissue FMU setting Python sets, with the FMU's default (docs/FMU_VARIABLES.md).
    for keyword in ("pcg_max_iterations=10", "gravity_m_per_s2=0 0 -9.81", "fixed_axis=2", "fixed_fraction=0.25",
                    "linear_solver=pcgTwoLevel (pcg, cholmod, pcgCholesky or pcgTwoLevel)",
                    "newton_max_iterations=1", "ida_relative_tolerance=0.0001",
                    "contact_stiffness_in_background=false", "max_tool_speed_m_per_s=5"):
        assert keyword in doc, keyword
    # A setting Python did not have by hand before the schema reaches the core.
    with pytest.raises(ValueError, match=r"cutter.vertexSnapFraction must be finite and in \[0, 0.5\)"):
        tissue.Tissue(box=(2, 2, 2), vertex_snap_fraction=0.5)  # added to the schema alone
    t = tissue.Tissue(box=(2, 2, 2), integrator="ida", ida_linear_solver="krylov", ida_max_order=2,
                      contact_spring_stiffness_n_per_m=500.0)
    assert t.contact_spring_stiffness_n_per_m == 500.0
    t.step(2)
    assert t.time_s == pytest.approx(0.002)
