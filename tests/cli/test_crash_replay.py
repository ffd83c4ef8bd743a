"""The crash-corpus replay (tests/fuzz/run.sh, in ./build.sh test) checks
something only when it has inputs: it must fail when the corpus is missing or
empty, and find its corpus from any working directory.
VOXLIGHT_CRASHERS points it at a temporary corpus."""
import os
import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RUN = ROOT / "tests" / "fuzz" / "run.sh"


def replay(cwd, corpus, *targets):
    env = dict(os.environ, VOXLIGHT_CRASHERS=str(corpus))
    out = subprocess.run([str(RUN), "replay", *targets], cwd=cwd, env=env,
                         capture_output=True, text=True, timeout=1800)
    return out.returncode, out.stdout + out.stderr


def test_every_fuzz_target_has_inputs_in_the_real_corpus():
    targets = sorted(p.stem[len("fuzz_"):] for p in (ROOT / "tests" / "fuzz").glob("fuzz_*.c"))
    assert len(targets) >= 7
    for t in targets:
        inputs = [p for p in (ROOT / "tests" / "crashers" / t).glob("*") if p.is_file() and not p.name.startswith(".")]
        assert inputs, f"tests/crashers/{t}/ holds no input"


def test_an_empty_corpus_fails(tmp_path):
    (tmp_path / "nifti").mkdir()
    (tmp_path / "nifti" / ".keep").write_bytes(b"")
    rc, out = replay(tmp_path, tmp_path, "nifti")
    assert rc == 1, out
    assert f"the crash corpus {tmp_path}/nifti/ is empty" in out
    assert out.strip().splitlines()[-1] == "0 passed, 1 failed"


def test_a_missing_corpus_fails(tmp_path):
    missing = tmp_path / "no-such-corpus"
    rc, out = replay(tmp_path, missing, "nifti", "nrrd")
    assert rc == 1, out
    assert f"the crash corpus {missing}/nifti/ is missing" in out
    assert out.strip().splitlines()[-1] == "0 passed, 2 failed"
    assert not missing.exists()  # the replay does not make up a corpus


def test_the_replay_runs_from_another_directory_with_a_relative_corpus(tmp_path):
    src = sorted(p for p in (ROOT / "tests" / "crashers" / "nifti").glob("*") if not p.name.startswith("."))[0]
    (tmp_path / "corpus" / "nifti").mkdir(parents=True)
    shutil.copy(src, tmp_path / "corpus" / "nifti" / src.name)
    work = tmp_path / "elsewhere"
    work.mkdir()
    rc, out = replay(work, "../corpus", "nifti")
    assert rc == 0, out
    assert f"fuzz_nifti: replayed 1 crashers from {tmp_path}/elsewhere/../corpus/nifti/: ok" in out
    assert out.strip().splitlines()[-1] == "1 passed, 0 failed"


def test_loaders_replays_the_corpus_from_any_directory_and_fails_on_none(tmp_path):
    """build/tests/test_loaders replays tests/crashers through vxl_volume_load
    (the dispatch by extension) too; it finds the corpus from its own path."""
    exe = ROOT / "build" / "tests" / "test_loaders"
    n = len([p for p in (ROOT / "tests" / "crashers").glob("*/*") if p.is_file() and not p.name.startswith(".")])
    env = {k: v for k, v in os.environ.items() if k != "VOXLIGHT_CRASHERS"}
    out = subprocess.run([str(exe)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert f"replayed {n} crashers from {ROOT}/tests/crashers" in out.stdout + out.stderr, out.stderr
    (tmp_path / "empty" / "nifti").mkdir(parents=True)
    out = subprocess.run([str(exe)], cwd=tmp_path, env=dict(env, VOXLIGHT_CRASHERS=str(tmp_path / "empty")),
                         capture_output=True, text=True, timeout=600)
    assert out.returncode != 0
    assert "no crasher replayed from" in out.stdout + out.stderr


def test_the_ci_fuzzing_reaches_the_same_coverage_on_every_run():
    """./build.sh test fuzzes our own parsers from a fixed seed for a fixed
    number of inputs: two runs must try the same inputs, so they reach the
    same coverage (before the fixed input path, the sorted seeds and
    -use_cmp=0, two runs of one seed parted ways within 20,000 inputs)."""
    env = dict(os.environ, VOXLIGHT_FUZZ_CI_RUNS="20000")
    lines = []
    for _ in range(2):
        out = subprocess.run([str(RUN), "ci", "label_table", "nrrd"], cwd=ROOT, env=env,
                             capture_output=True, text=True, timeout=1800)
        assert out.returncode == 0, out.stdout + out.stderr
        got = [l for l in out.stdout.splitlines() if "inputs from seed" in l]
        assert len(got) == 2 and all("20000 inputs" in l and "cov: " in l for l in got), out.stdout
        lines.append(got)
    assert lines[0] == lines[1]
