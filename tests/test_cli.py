"""The command line as a user meets it: help, version, exit codes, summaries."""

from __future__ import annotations

import json
from pathlib import Path
from typing import cast

import numpy as np
import pytest

from conftest import EXAMPLES, REPO, run_cli
from creaturegen import __version__, cli, cli_build
from creaturegen.cli_errors import EXIT_GATE_FAILED, EXIT_INVALID, EXIT_OK, EXIT_REFUSED
from creaturegen.field.sampler import sample
from creaturegen.motion.compiled import compile_creature
from creaturegen.rig import compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.build import SurfaceBuild


def test_version() -> None:
    done = run_cli("--version")
    assert (done.returncode, done.stdout.strip()) == (0, f"creaturegen {__version__}")


def test_help_lists_commands_and_exit_codes() -> None:
    done = run_cli("--help")
    assert done.returncode == 0
    for word in ("validate", "schema", "build", "Exit codes"):
        assert word in done.stdout
    flat = " ".join(done.stdout.split())
    assert "2 invalid spec or arguments" in flat
    assert "3 a valid spec that a build gate refuses" in flat


def test_no_command_is_a_usage_error() -> None:
    assert run_cli().returncode == 2


def test_validate_many_files_ok() -> None:
    files = [str(p) for p in sorted(EXAMPLES.rglob("*.json"))]
    done = run_cli("validate", *files)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [f"{f}: ok" for f in files]


def test_one_bad_file_among_good_ones_fails_therun_cli() -> None:
    good = str(EXAMPLES / "lizard.json")
    bad = str(REPO / "tests" / "fixtures" / "invalid" / "k-exceeds-kcap.json")
    done = run_cli("validate", good, bad)
    assert done.returncode == 2
    assert done.stdout.strip() == f"{good}: ok"
    assert done.stderr.strip() == f"{bad}: part.head.k: must be <= kCap (0.05) (got 0.2)"


def test_build_prints_the_compiled_summary(tmp_path: Path) -> None:
    # The moth: an explicit blend tree with two roots, and a surface test_surface_build extracts anyway (the
    # run's shared cache), so this reads the summary rather than paying for another surface and picture.
    done = run_cli("build", str(EXAMPLES / "moth.json"), "-o", str(tmp_path / "out"), "--picture", "off")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert "creature 'Moth Two Roots' -> package moth-two-roots" in lines
    assert "  parts 1 capsule, 2 cone, 1 rope, 1 sphere (5 in all)" in lines
    assert "  slots 7 of maxParts 64" in lines
    assert "  blend tree, 3 nodes, 2 root(s)" in lines


def test_schema_check_detects_staleness(tmp_path: Path) -> None:
    assert run_cli("schema", "--check", "--out", str(tmp_path)).returncode == 2
    assert run_cli("schema", "--out", str(tmp_path)).returncode == 0
    assert run_cli("schema", "--check", "--out", str(tmp_path)).returncode == 0


def test_probe_json_matches_the_sampler(tmp_path: Path) -> None:
    points = [[0.0, 1.3, 0.2], [0.1, 0.5, -0.3], [0.4, 0.2, 0.1]]
    path = tmp_path / "points.npy"
    np.save(path, np.array(points))
    done = run_cli("probe", str(EXAMPLES / "reference" / "biped.json"), "--points", str(path), "--json")
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    spec = load_spec(EXAMPLES / "reference" / "biped.json")
    assert isinstance(spec, CharacterSpec)
    expected = sample(compile_rig(spec), np.array(points))
    assert result["distance"] == expected.distance.tolist()
    assert result["gradient"] == expected.gradient.tolist()
    assert result["color"] == expected.color.tolist()


def test_probe_rejects_bad_points(tmp_path: Path) -> None:
    path = tmp_path / "points.json"
    path.write_text("[[0, 1], [2, 3]]")
    done = run_cli("probe", str(EXAMPLES / "moth.json"), "--points", str(path))
    assert done.returncode == 2
    assert done.stderr.strip() == f"{path}: must be an array of [x, y, z] with finite numbers"


def test_probe_of_a_frost_spec_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "points.json"
    path.write_text("[[0, 0, 0]]")
    spec = EXAMPLES / "frost" / "frost-full.json"
    done = run_cli("probe", str(spec), "--points", str(path))
    assert done.returncode == 2
    assert done.stderr.strip() == f"{spec}: kind: must be creature for this command"


def test_inspect_json_reports_slots_program_and_signatures() -> None:
    done = run_cli("inspect", str(EXAMPLES / "beetle.json"), "--json", "--tiers", "hero")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    hero = report["candidates"]["hero"]
    assert hero["status"] == "accepted"
    assert all(g["passed"] for g in hero["gates"])
    assert set(hero["certificates"]) >= {"lse-tail", "colour-weight"}
    assert report["slotCount"] == len(report["slots"]) == 16
    assert {op["kernel"] for op in report["blend"]["ops"]} == {"poly", "lse"}
    assert set(report["signatures"]) == {"compilerSignature", "topologySignature", "geometryDigest"}
    assert report["compiler"]["floors"]["k_floor"] == 1e-3 * report["bodyScale"]


def test_inspect_says_the_lower_tiers_use_the_skin_representation() -> None:
    done = run_cli("inspect", str(EXAMPLES / "moth.json"), "--tiers", "repeated,distant")
    assert done.returncode == 0, done.stderr
    for tier in ("repeated", "distant"):
        assert f"candidates {tier}: skin: tier {tier}: skin representation" in done.stdout


def test_inspect_rejects_an_unknown_tier() -> None:
    done = run_cli("inspect", str(EXAMPLES / "moth.json"), "--tiers", "hero,epic")
    assert done.returncode == 2
    assert done.stderr.strip() == "--tiers: unknown tier 'epic' (known: hero, repeated, distant)"


PINCER = REPO / "tests" / "fixtures" / "pincer.json"


def test_a_valid_spec_a_build_gate_refuses_exits_3_and_writes_nothing(tmp_path: Path) -> None:
    """The pincer validates (exit 0) but its two claws touch and close a handle, so the euler gate refuses
    its surface: exit 3, not 2 (the spec is well formed; its shape must change), and nothing is written
    (an earlier package and a user's file in the output folder are left as they were). The pincer, and not
    the tangled beetle of tests/test_surface_handles.py, because it refuses in 3 s: the beetle's hexapod
    motion envelope runs first and takes 40."""
    assert run_cli("validate", str(PINCER)).returncode == 0
    out = tmp_path / "out"
    (out / "pincer").mkdir(parents=True)
    (out / "pincer" / "index.js").write_text("// an earlier build\n")
    (out / "notes.txt").write_text("mine")
    before = sorted(
        (p.relative_to(out).as_posix(), p.read_bytes() if p.is_file() else b"") for p in out.rglob("*")
    )
    done = run_cli("build", str(PINCER), "-o", str(out), "--picture", "off")
    assert done.returncode == 3, done.stdout[-2000:] + done.stderr[-2000:]
    assert f"{PINCER}: surface.hero: surface hero: gate euler" in done.stderr
    assert "part.claw-right touches part.claw-left" in done.stderr
    assert "Traceback" not in done.stderr
    after = sorted(
        (p.relative_to(out).as_posix(), p.read_bytes() if p.is_file() else b"") for p in out.rglob("*")
    )
    assert after == before


def test_posed_skin_faults_are_reported_by_default_and_refused_on_request(tmp_path: Path) -> None:
    """The hopper's counter-tail folds its skin out of the body at a pose of its own hop cycle
    (surface/posed.py). By default the build writes the package, prints a warning naming the gate and
    records the gates in the build report; with --posed-gates refuse the same surface (a cache hit the
    second time) is refused with exit 3, naming the part and the pose, and nothing is written."""
    spec = EXAMPLES / "reference" / "hopper.json"
    out = tmp_path / "out"
    done = run_cli("build", str(spec), "-o", str(out), "--picture", "off")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "warning: posed skin: posed.folds =" in done.stdout
    report = json.loads((out / "hopper-squash-core" / "build-report.json").read_text())
    posed = {g["name"]: g for g in report["surface"]["posedGates"]}
    assert set(posed) == {"posed.inverted", "posed.folds", "posed.selfIntersections"}
    assert not posed["posed.folds"]["passed"]
    refused = tmp_path / "refused"
    done = run_cli("build", str(spec), "-o", str(refused), "--picture", "off", "--posed-gates", "refuse")
    assert done.returncode == 3, done.stderr[-2000:]
    assert f"{spec}: surface.hero: surface hero posed skin: gate posed.folds" in done.stderr
    assert "part.counter-tail" in done.stderr
    assert "worst in the envelope pose '" in done.stderr
    assert "Traceback" not in done.stderr
    assert not refused.exists()


def test_population_short_of_n_identities_exits_3(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """--population N on a valid spec whose variants every gate refuses: the authored identity passed, so
    the spec is valid and the refusal is a gate's, exit 3, with nothing written. The surface is stubbed:
    which identities pass is the only thing under test here."""
    source = EXAMPLES / "reference" / "hopper.json"
    spec = load_spec(source)
    assert isinstance(spec, CharacterSpec)

    def identity(
        args: object, name: str, one: CharacterSpec, data: bytes
    ) -> cli_build._Identity | int:  # the authored identity passes, every variant is refused
        if name != str(source):
            return EXIT_REFUSED
        return cli_build._Identity(name, compile_creature(one), data, cast(SurfaceBuild, None))

    monkeypatch.setattr(cli_build, "_identity", identity)
    out = tmp_path / "out"
    code = cli.main(["build", str(source), "-o", str(out), "--population", "2", "--picture", "off"])
    assert code == EXIT_REFUSED == 3
    assert "only 1 of 2 identities passed every gate in 8 draws" in capsys.readouterr().err
    assert not out.exists()


def test_exit_codes_are_distinct() -> None:
    codes = (EXIT_OK, EXIT_GATE_FAILED, EXIT_INVALID, EXIT_REFUSED)
    assert codes == (0, 1, 2, 3)
