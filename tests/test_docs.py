"""Every Python example of the README and the documentation runs as written: each block is saved
to a file and run by a fresh interpreter in an empty folder, as a user pasting it would."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import pynastran_imports

REPO = Path(__file__).resolve().parent.parent
SOURCES = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```$", re.MULTILINE | re.DOTALL)


def blocks() -> list[tuple[str, str]]:
    found = []
    for path in SOURCES:
        text = path.read_text()
        for match in BLOCK.finditer(text):
            line = text.count("\n", 0, match.start()) + 1
            found.append((f"{path.relative_to(REPO)}:{line}", match.group(1)))
    return found


BLOCKS = blocks()
NEEDS_PYNASTRAN = "# needs pyNastran"
"""The first line of an example that needs the optional extra thermojitter[nastran]."""


def test_the_docs_have_examples() -> None:
    names = {name.split(":")[0] for name, _ in BLOCKS}
    assert "README.md" in names and any(n.startswith("docs/") for n in names)


@pytest.mark.parametrize("code", [code for _, code in BLOCKS], ids=[name for name, _ in BLOCKS])
def test_example_runs_as_written(code: str, tmp_path: Path) -> None:
    if code.startswith(NEEDS_PYNASTRAN) and not pynastran_imports():
        pytest.skip("pyNastran (thermojitter[nastran]) does not import here")
    script = tmp_path / "example.py"
    script.write_text(code)
    done = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Traceback" not in done.stderr
    # Dask finding its dashboard port taken, or any other warning, is a flaw in an example.
    assert "Warning" not in done.stderr, done.stderr[-3000:]


def test_every_scenario_key_is_documented() -> None:
    """The scenario reference and ``run --help`` name every key the parser accepts."""
    from dataclasses import fields

    from thermojitter import _core
    from thermojitter.cli.flutter import FLUTTER_KEYS
    from thermojitter.cli.mc import RUN_KEYS, SETTING_KEYS
    from thermojitter.cli.run import scenario_keys_help
    from thermojitter.orbit import Orbit
    from thermojitter.scenario import SimulationSettings

    reference = (REPO / "docs" / "scenarios.md").read_text()
    run_help = scenario_keys_help()
    common = [
        *_core.PANEL_FIELDS,
        "preset",
        "start_date",
        "altitude",
        *(f.name for f in fields(Orbit)),
        *(f.name for f in fields(SimulationSettings)),
        "format",
        "plots",
    ]
    for key in common:
        assert f"| `{key}` |" in reference, key
        assert re.search(rf"\b{key}\b", run_help), key
    from thermojitter.scenario import LAMINATE_KEYS, LAYER_KEYS

    for key in (*LAMINATE_KEYS, "layers", *LAYER_KEYS):
        assert f"| `{key}` |" in reference, key
        assert re.search(rf"\b{key}\b", run_help), key
    for key in (*FLUTTER_KEYS, *SETTING_KEYS, *RUN_KEYS):
        assert f"| `{key}` |" in reference, key


def test_the_install_commands_warn_that_a_plain_install_replaces_an_editable_one() -> None:
    """``pip install ".[cli]"`` in a checkout installed with ``pip install -e`` silently turns it
    into a copy: every page that shows the plain install says so, and how to keep it editable."""
    for path in (REPO / "README.md", REPO / "docs" / "getting-started.md"):
        text = " ".join(path.read_text().split())
        assert 'pip install ".[cli]"' in text, path.name
        assert "replaces an editable install" in text, path.name
        assert 'pip install -e ".[cli]"' in text, path.name
