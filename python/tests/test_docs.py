"""docs/PYTHON.md's example runs as printed (the docs stay true)."""
import pathlib
import re

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "PYTHON.md"


def test_the_example_in_the_docs_runs():
    text = DOC.read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "docs/PYTHON.md has no python example"
    namespace = {}
    exec(compile(blocks[0], str(DOC), "exec"), namespace)  # noqa: S102 - our own document
    frog = namespace["frog"]
    assert namespace["cut"] > 0  # the stroke cut
    assert frog.cut_tets == 0  # and the restore undid it
    points, triangles = namespace["points"], namespace["triangles"]
    assert points.shape[1] == 3 and triangles.shape[1] == 3


def test_the_scenario_example_in_the_docs_runs(monkeypatch):
    text = DOC.read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 2, "docs/PYTHON.md has no scenario example"
    monkeypatch.chdir(DOC.parents[1])  # the example names the scenario from the checkout's root
    namespace = {}
    exec(compile(blocks[1], str(DOC), "exec"), namespace)  # noqa: S102 - our own document
    force_z = namespace["frog"].contact["force_on_tool_n"][2]
    assert 1.0 < force_z < 2.0  # the press held 3 mm in


def test_the_haptic_loop_example_in_the_docs_runs_and_every_keyword_is_listed():
    import tissue

    text = DOC.read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 3, "docs/PYTHON.md has no haptic loop example"
    namespace = {}
    exec(compile(blocks[2], str(DOC), "exec"), namespace)  # noqa: S102 - our own document
    assert namespace["force"][2] > 0.5  # the scripted hand pressed 4 mm in: the tissue pushes back
    for keyword in tissue.HapticLoop.fmu_names:
        assert f"`{keyword}`" in text, keyword
