"""The shipped sweep files load, and the examples README documents every task's columns."""

import pytest

from taut.sweep import TASKS, load_sweep


@pytest.mark.parametrize("name", ["octagon_stability", "corridor_robustness",
                                  "fastkit_coverage", "octagon_stability_small"])
def test_example_sweeps_load(examples_dir, name):
    spec = load_sweep(examples_dir / "sweeps" / f"{name}.yaml")
    assert spec.size >= {"octagon_stability": 100_000, "corridor_robustness": 1000}.get(name, 1)


def test_readme_lists_every_parameter_and_output(examples_dir):
    text = (examples_dir / "sweeps" / "README.md").read_text()
    for task in TASKS.values():
        assert f"`{task.name}`" in text
        for name in (*task.parameters, *task.outputs):
            assert f"| `{name}` |" in text, (task.name, name)
