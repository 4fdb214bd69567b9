# SPDX-License-Identifier: MIT
"""Faults around a run (issue 14): a full disk, kills while files are rewritten, files
of other tools in the output folder, two runs into one folder, more than 99 999 steps,
input files changed before a restart, damaged restart files, and files too large for
memory. Each must end with a message and the documented exit code, and keep what
converged before it. Every subprocess is bounded in time."""
from __future__ import annotations

import contextlib
import csv
import os
import resource
import signal
import struct
import subprocess
import threading
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from yarnfort import read_state
from test_restart import CAPSTAN, VNET, compare_curves, folder_content, read_rows, with_output

TOP = Path(__file__).resolve().parents[2]
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
#: Seconds any single run may take (the scenes here take well under one).
TIMEOUT = 120
CRASH_MARKERS = ("Fortran runtime", "Program received signal", "Backtrace", "ERROR STOP",
                 "Segmentation fault", "core dumped")

#: The capstan scene in 1000 small steps (a run long enough to be caught part way).
LONG_CAPSTAN = CAPSTAN.replace("max_step = 0.05", "max_step = 0.002\n    initial_step = 0.002")


def run(text: str, cwd: Path, *, memory: int | None = None,
        file_size: int | None = None) -> subprocess.CompletedProcess:
    """Run yarnfort on `text` in `cwd`, optionally with its address space limited to
    `memory` bytes, or its files to `file_size` bytes (a write past it fails: EFBIG)."""
    def limit() -> None:
        if memory:
            resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        if file_size:
            resource.setrlimit(resource.RLIMIT_FSIZE, (file_size, file_size))

    proc = subprocess.run([str(EXECUTABLE)], input=text, capture_output=True, text=True,
                          cwd=cwd, timeout=TIMEOUT,
                          preexec_fn=limit if memory or file_size else None)
    for marker in CRASH_MARKERS:
        assert marker not in proc.stderr, proc.stderr
    return proc


def start(text: str, cwd: Path) -> subprocess.Popen:
    """Start yarnfort on `text` in `cwd`; a watchdog kills it after TIMEOUT seconds, so
    that reading its progress lines can never block for longer."""
    process = subprocess.Popen([str(EXECUTABLE)], cwd=cwd, text=True, stdin=subprocess.PIPE,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    watchdog = threading.Timer(TIMEOUT, process.kill)
    watchdog.daemon = True
    watchdog.start()
    process.stdin.write(text)
    process.stdin.close()
    return process


def wait_for_step(process: subprocess.Popen, step: int) -> None:
    """Read the run's progress lines until it reports `step` (fails if it ends first)."""
    for line in process.stderr:
        if line.startswith("step") and int(line.split()[1]) >= step:
            return
    raise AssertionError("the run ended (or was stopped by the watchdog) before step %d"
                         % step)


def collection(folder: Path) -> list[tuple[str, str]]:
    """The states listed (the yarns' file of each multiblock file) and their times."""
    root = ET.parse(folder / "states.pvd").getroot()
    return [(yarns_file(folder / d.get("file")), d.get("timestep"))
            for d in root.iter("DataSet")]


def yarns_file(multiblock: Path) -> str:
    """The yarns' block of a state's multiblock file (state_NNNNN.vtm)."""
    root = ET.parse(multiblock).getroot()
    return next(d.get("file") for d in root.iter("DataSet") if d.get("name") == "yarns")


def complete_rows(folder: Path) -> list[list[str]]:
    """The rows of curve.csv, each checked to have every column."""
    with open(folder / "curve.csv", newline="") as stream:
        rows = list(csv.reader(stream))
    assert all(len(row) == len(rows[0]) for row in rows), "a row is cut short"
    return rows[1:]


# ------------------------------------------------------------------ a full disk

@pytest.fixture
def small_disk(tmp_path):
    """A tmpfs mounted at tmp_path/disk (root only), resized by calling it with a size."""
    if os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs needs root (CI runs as root)")
    mount = tmp_path / "disk"
    mount.mkdir()
    mounted = []

    def resize(size: str) -> Path:
        options = f"size={size}" if not mounted else f"remount,size={size}"
        proc = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(mount)],
                              capture_output=True, text=True, timeout=30)
        if proc.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here: {proc.stderr.strip()}")
        mounted.append(size)
        return mount

    yield resize
    if mounted:
        subprocess.run(["umount", "-l", str(mount)], capture_output=True, timeout=30)


def test_full_disk_ends_the_run_and_keeps_the_restart_file(small_disk, tmp_path):
    """64 kB fill up after about ten steps: the run stops with exit 1 and says why; the
    curve holds only whole rows, states.pvd lists only whole states, and the restart
    file is the last good one: with room again, a restart gives the uninterrupted
    curve."""
    full = run(with_output(CAPSTAN, "full"), tmp_path)
    assert full.returncode == 0, full.stderr
    disk = small_disk("64k")
    proc = run(with_output(CAPSTAN, "disk/out"), tmp_path)
    assert proc.returncode == 1, proc.stderr
    assert "yarnfort: error (output): cannot write 'disk/out/" in proc.stderr
    assert "No space left on device" in proc.stderr
    assert "done" not in proc.stderr
    out = disk / "out"
    rows = complete_rows(out)
    assert 1 <= len(rows) < len(read_rows(tmp_path / "full"))
    listed = collection(out)
    assert listed, "states.pvd lists no state"
    for name, _ in listed:
        assert len(read_state(out / name).tension) == 7
    assert (out / "restart.dat").read_bytes().startswith(b"yarnfort-restart")
    assert not list(out.glob("*.tmp"))
    small_disk("4m")
    again = run(with_output(CAPSTAN, "disk/out", control="restart = .true."), tmp_path)
    assert again.returncode == 0, again.stderr
    compare_curves(read_rows(tmp_path / "full"), read_rows(out))
    assert collection(out) == collection(tmp_path / "full")


def test_curve_row_that_fails_part_way_is_cut_off(tmp_path):
    """Files may not grow past 6000 bytes: the curve row that crosses it is written only
    in part. The run stops with exit 1 and the reason, and curve.csv keeps whole rows;
    a restart (without the limit) gives the uninterrupted curve."""
    # Only curve.csv grows (contacts.csv, on by default with passages, would pass the
    # limit first).
    only_curve = "vtk_every = 0, contact_state = .false."
    full = run(with_output(CAPSTAN, "full", output=only_curve), tmp_path)
    assert full.returncode == 0, full.stderr
    proc = run(with_output(CAPSTAN, "out", output=only_curve), tmp_path, file_size=6000)
    assert proc.returncode == 1, proc.stderr
    assert "yarnfort: error (output): cannot write 'out/curve.csv': File too large" in proc.stderr
    rows = complete_rows(tmp_path / "out")
    assert 5 <= len(rows) < len(read_rows(tmp_path / "full"))
    assert (tmp_path / "out" / "curve.csv").stat().st_size < 6000
    again = run(with_output(CAPSTAN, "out", control="restart = .true.",
                            output=only_curve), tmp_path)
    assert again.returncode == 0, again.stderr
    compare_curves(read_rows(tmp_path / "full"), read_rows(tmp_path / "out"))


@pytest.mark.parametrize("size", ["4k", "12k"])
def test_disk_full_before_the_first_step(small_disk, tmp_path, size):
    """No room for the run's bookkeeping files or input.nml: exit 2 before any solve,
    with the file and the reason named."""
    small_disk(size)
    proc = run(with_output(CAPSTAN, "disk/out"), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "yarnfort: error (output): cannot write 'disk/out/" in proc.stderr
    assert "No space left on device" in proc.stderr
    assert not (tmp_path / "disk" / "out" / "restart.dat").exists()


# ------------------------------------------------------------------ foreign files

def test_files_of_other_tools_are_never_deleted(tmp_path):
    """A states.pvd (and a manifest) of another tool list files; the run deletes none of
    them. The next run deletes the states of the first that it does not write again."""
    out = tmp_path / "out"
    out.mkdir()
    foreign = {"notes.txt": b"mine", "state_00099.vtu": b"not yarnfort's",
               "measured.csv": b"1,2\n"}
    for name, data in foreign.items():
        (out / name).write_bytes(data)
    (tmp_path / "outside.txt").write_bytes(b"outside")
    listing = "".join(f'<DataSet timestep="0" file="{name}"/>\n'
                      for name in [*foreign, "../outside.txt"])
    (out / "states.pvd").write_text(f"<VTKFile><Collection>\n{listing}</Collection></VTKFile>")
    (out / ".yarnfort-manifest").write_text("file notes.txt\nfile ../outside.txt\n"
                                            "state measured.csv 1 0.0\n")
    first = run(with_output(VNET, "out"), tmp_path)
    assert first.returncode == 0, first.stderr
    for name, data in foreign.items():
        assert (out / name).read_bytes() == data, name
    assert (tmp_path / "outside.txt").read_bytes() == b"outside"
    n_first = len(collection(out))
    assert n_first > 3
    second = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert second.returncode == 0, second.stderr
    assert sorted(p.name for p in out.glob("state_*.vtu")) == [
        "state_00000.vtu", "state_00001.vtu", "state_00002.vtu", "state_00099.vtu"]
    for name, data in foreign.items():
        assert (out / name).read_bytes() == data, name


def test_restart_file_of_another_program_is_left_alone(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "restart.dat").write_bytes(b"someone else's restart data")
    proc = run(with_output(VNET, "out", control="max_steps = 1"), tmp_path)
    assert proc.returncode == 0, proc.stderr
    # Replaced by this run's own (written through restart.dat.tmp), never read.
    assert (out / "restart.dat").read_bytes().startswith(b"yarnfort-restart")


# ------------------------------------------------------------------ the manifest (issue 39)

def manifest_files(folder: Path) -> set[str]:
    """The fixed names the folder's manifest lists (its 'file' lines)."""
    lines = (folder / ".yarnfort-manifest").read_text().splitlines()
    return {line.split()[1] for line in lines if line.startswith("file ")}


def test_manifest_lists_only_what_the_run_wrote(tmp_path):
    """A run lists the names it wrote (and their temporaries), not every name it may
    write: vnet asks for no reactions.csv and has no sliding passages (no contacts.csv).
    Tables of one's own of those names survive the next run; a reactions.csv the run
    did write is deleted by a run that writes none (it would be stale)."""
    out = tmp_path / "out"
    first = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert first.returncode == 0, first.stderr
    listed = manifest_files(out)
    written = {p.name for p in out.iterdir()} - {".yarnfort-lock", ".yarnfort-manifest"}
    written -= {name for name in written if name.startswith("state_")}
    # restart.sync: the restart file last flushed to disk (a second name of restart.dat).
    assert written == {"curve.csv", "input.nml", "restart.dat", "restart.sync", "states.pvd"}
    assert listed == written | {name + ".tmp" for name in written} - {"curve.csv.tmp"}
    mine = {"reactions.csv": b"my,own\n1,2\n", "contacts.csv": b"measured\n3\n",
            "reactions.csv.tmp": b"draft"}
    for name, data in mine.items():
        (out / name).write_bytes(data)
    second = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert second.returncode == 0, second.stderr
    for name, data in mine.items():
        assert (out / name).read_bytes() == data, name
    # A run that writes reactions.csv replaces it (a name it writes) and lists it ...
    third = run(with_output(VNET, "out", control="max_steps = 2",
                            output="node_reactions = .true."), tmp_path)
    assert third.returncode == 0, third.stderr
    assert (out / "reactions.csv").read_bytes().startswith(b"step,")
    assert "reactions.csv" in manifest_files(out)
    # ... so a later run without it deletes it, and only it.
    fourth = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert fourth.returncode == 0, fourth.stderr
    assert not (out / "reactions.csv").exists()
    assert (out / "contacts.csv").read_bytes() == mine["contacts.csv"]
    assert (out / "reactions.csv.tmp").read_bytes() == mine["reactions.csv.tmp"]


def test_restart_keeps_tables_it_never_wrote(tmp_path):
    """A restart that writes no reactions.csv or contacts.csv deletes them only when a
    run of ours wrote them (listed): one's own stay."""
    out = tmp_path / "out"
    first = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert first.returncode == 0, first.stderr
    mine = {"reactions.csv": b"my,own\n", "contacts.csv": b"measured\n"}
    for name, data in mine.items():
        (out / name).write_bytes(data)
    again = run(with_output(VNET, "out", control="restart = .true."), tmp_path)
    assert again.returncode == 0, again.stderr
    for name, data in mine.items():
        assert (out / name).read_bytes() == data, name
    # Written by the first run, not by its restart: deleted.
    first = run(with_output(VNET, "own", control="max_steps = 2",
                            output="node_reactions = .true."), tmp_path)
    assert first.returncode == 0, first.stderr
    assert (tmp_path / "own" / "reactions.csv").exists()
    again = run(with_output(VNET, "own", control="restart = .true."), tmp_path)
    assert again.returncode == 0, again.stderr
    assert not (tmp_path / "own" / "reactions.csv").exists()
    assert "reactions.csv" not in manifest_files(tmp_path / "own")


# ------------------------------------------------------------------ links (issue 39)

#: Every name the program writes in an output folder (vnet writes all but the
#: reactions.csv ones with node_reactions; the capstan scene writes contacts.csv).
WRITTEN_NAMES = ("curve.csv", "curve.csv.tmp", "input.nml", "input.nml.tmp", "restart.dat",
                 "restart.dat.tmp", "states.pvd", "states.pvd.tmp", "reactions.csv",
                 "reactions.csv.tmp", "contacts.csv", "contacts.csv.tmp", "state_00000.vtu",
                 "state_00003.vtu", "state_00000.vtm", "state_00003.vtm",
                 ".yarnfort-manifest", ".yarnfort-manifest.tmp",
                 ".yarnfort-lock", ".yarnfort-write-test")


def symlinks_supported(tmp_path: Path) -> None:
    try:
        os.symlink("target", tmp_path / "probe-link")
    except (OSError, NotImplementedError) as error:
        pytest.skip(f"cannot create symbolic links here: {error}")
    (tmp_path / "probe-link").unlink()


def tree(folder: Path) -> dict[str, object]:
    """Every entry under `folder`, not following links: a file's bytes, a link's target,
    None for a folder (the lock file's line, rewritten by every run, left out)."""
    content: dict[str, object] = {}
    for top, folders, files in os.walk(folder):        # (never into a linked folder)
        for entry in sorted([*folders, *files]):
            path = Path(top) / entry
            name = str(path.relative_to(folder))
            if path.is_symlink():
                content[name] = ("link", os.readlink(path))
            elif path.is_dir():
                content[name] = None
            elif entry != ".yarnfort-lock":
                content[name] = path.read_bytes()
    return content


@pytest.mark.parametrize("dangling", [False, True], ids=["to-a-file", "dangling"])
@pytest.mark.parametrize("name", WRITTEN_NAMES)
def test_link_at_a_written_name_is_refused(tmp_path, name, dangling):
    """A symbolic link at any name the program writes, pointing out of the folder (to a
    file, or to none yet): exit 2 before the first step, the link named; the file it
    points to is neither written, truncated nor created, and the folder (an earlier
    run's files, the link) stays as it was."""
    symlinks_supported(tmp_path)
    scene = CAPSTAN if name.startswith("contacts") else VNET
    outside = tmp_path / "outside.txt"
    if not dangling:
        outside.write_bytes(b"precious, outside the output folder\n")
    first = run(with_output(scene, "out", control="max_steps = 1"), tmp_path)
    assert first.returncode == 0, first.stderr
    out = tmp_path / "out"
    link = out / name
    if link.exists():
        link.unlink()
    os.symlink(outside, link)
    before = tree(tmp_path)
    proc = run(with_output(scene, "out", output="node_reactions = .true."), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert f"'out/{name}' is a symbolic link" in proc.stderr, proc.stderr
    assert tree(tmp_path) == before
    if dangling:
        assert not outside.exists()


def test_link_at_the_lock_is_refused_in_a_new_folder(tmp_path):
    """Item 2 of issue 39: .yarnfort-lock linked to a file outside: that file keeps its
    bytes (it was overwritten with 'pid ... host ... since ...')."""
    symlinks_supported(tmp_path)
    outside = tmp_path / "outside.txt"
    outside.write_bytes(b"precious\n")
    (tmp_path / "out").mkdir()
    os.symlink("../outside.txt", tmp_path / "out" / ".yarnfort-lock")
    proc = run(with_output(VNET, "out"), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "'out/.yarnfort-lock' is a symbolic link" in proc.stderr
    assert outside.read_bytes() == b"precious\n"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [".yarnfort-lock"]


def test_link_at_the_write_probe_is_refused(tmp_path):
    """Item 3 of issue 39: .yarnfort-write-test linked to a file outside: that file is
    not truncated."""
    symlinks_supported(tmp_path)
    outside = tmp_path / "outside.txt"
    outside.write_bytes(b"precious\n")
    (tmp_path / "out").mkdir()
    os.symlink(outside, tmp_path / "out" / ".yarnfort-write-test")
    proc = run(with_output(VNET, "out"), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "'out/.yarnfort-write-test' is a symbolic link" in proc.stderr
    assert outside.read_bytes() == b"precious\n"
    assert (tmp_path / "out" / ".yarnfort-write-test").is_symlink()


def test_hard_link_at_the_lock_is_refused(tmp_path):
    """The run's line is written into the lock file: one with another name (a hard link
    to a file outside the folder) is refused."""
    outside = tmp_path / "outside.txt"
    outside.write_bytes(b"precious\n")
    (tmp_path / "out").mkdir()
    try:
        os.link(outside, tmp_path / "out" / ".yarnfort-lock")
    except OSError as error:
        pytest.skip(f"cannot create hard links here: {error}")
    proc = run(with_output(VNET, "out"), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "'out/.yarnfort-lock' is not a regular file of its own" in proc.stderr
    assert outside.read_bytes() == b"precious\n"


def test_hard_links_at_written_names_keep_their_content(tmp_path):
    """A file the run writes gets a new file under its name: another name of the old
    one (a hard link to a file outside) keeps its content."""
    outside = {name: tmp_path / f"outside_{name}" for name in
               ("curve.csv", "state_00000.vtu", "restart.dat", "input.nml.tmp")}
    (tmp_path / "out").mkdir()
    try:
        for name, path in outside.items():
            path.write_bytes(b"precious " + name.encode())
            os.link(path, tmp_path / "out" / name)
    except OSError as error:
        pytest.skip(f"cannot create hard links here: {error}")
    proc = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert proc.returncode == 0, proc.stderr
    for name, path in outside.items():
        assert path.read_bytes() == b"precious " + name.encode(), name
    assert (tmp_path / "out" / "curve.csv").read_bytes().startswith(b"step,")


def test_links_of_other_names_are_left_alone(tmp_path):
    """Links of one's own in the output folder at names the program never writes are
    no reason to refuse, and the run leaves them (and what they point to) alone."""
    symlinks_supported(tmp_path)
    outside = tmp_path / "outside.txt"
    outside.write_bytes(b"precious\n")
    (tmp_path / "out").mkdir()
    for name in ("data.csv", "state_1.vtu", "curve.csv.bak"):
        os.symlink(outside, tmp_path / "out" / name)
    proc = run(with_output(VNET, "out", control="max_steps = 2"), tmp_path)
    assert proc.returncode == 0, proc.stderr
    for name in ("data.csv", "state_1.vtu", "curve.csv.bak"):
        assert os.readlink(tmp_path / "out" / name) == str(outside)
    assert outside.read_bytes() == b"precious\n"


def test_output_folder_reached_through_a_link(tmp_path):
    """The &output folder's own path may lead through a link (the folder one named):
    the files go to where it leads, the link stays."""
    symlinks_supported(tmp_path)
    (tmp_path / "scratch" / "out").mkdir(parents=True)
    os.symlink(tmp_path / "scratch", tmp_path / "results")
    proc = run(with_output(VNET, "results/out", control="max_steps = 1"), tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "results").is_symlink()
    assert (tmp_path / "scratch" / "out" / "curve.csv").is_file()


# ------------------------------------------------------------------ folder names (issue 39)

@pytest.mark.parametrize("existing", ["", "kept/"])
def test_refused_folder_name_leaves_no_parent_behind(tmp_path, existing):
    """Item 10 of issue 39: a folder name with a 300-character component is refused
    (exit 2, the reason named) and the folders on the way to it that the run created
    are removed again; one that was there stays."""
    if existing:
        (tmp_path / existing).mkdir()
    folder = existing + "new/deeper/" + "x" * 300 + "/out"
    proc = run(with_output(VNET, folder), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert f"folder '{folder}' cannot be created or written: " in proc.stderr
    assert "too long" in proc.stderr.lower()      # ENAMETOOLONG, in the C library's words
    assert sorted(p.name for p in tmp_path.iterdir()) == ([existing[:-1]] if existing else [])
    if existing:
        assert list((tmp_path / existing).iterdir()) == []


# ------------------------------------------------------------------ kills

@pytest.mark.parametrize("signal_number", [signal.SIGKILL, signal.SIGTERM])
def test_states_pvd_survives_kills(tmp_path, signal_number):
    """Kill the run at several moments: states.pvd is always whole and lists only whole
    states (at most 5 % behind the written ones); a restart lists every state."""
    full = run(with_output(LONG_CAPSTAN, "full"), tmp_path)
    assert full.returncode == 0, full.stderr
    everything = collection(tmp_path / "full")
    out = tmp_path / "parts"
    for kill_at in (3, 40, 130, 260, 410):
        control = "restart = .true." if (out / "restart.dat").exists() else ""
        process = start(with_output(LONG_CAPSTAN, "parts", control=control), tmp_path)
        wait_for_step(process, kill_at)
        process.send_signal(signal_number)
        process.stderr.close()
        assert process.wait(timeout=TIMEOUT) == -signal_number
        listed = collection(out)
        written = list(out.glob("state_*.vtu"))
        assert len(listed) >= 0.95 * len(written) - 1
        assert [name for name, _ in listed] == [name for name, _ in everything[:len(listed)]]
        for name, _ in listed[-3:]:
            assert len(read_state(out / name).tension) == 7
    again = run(with_output(LONG_CAPSTAN, "parts", control="restart = .true."), tmp_path)
    assert again.returncode == 0, again.stderr
    assert collection(out) == everything
    compare_curves(read_rows(tmp_path / "full"), read_rows(out))


# ------------------------------------------------------------------ concurrent runs

def test_second_run_into_a_folder_fails_fast(tmp_path):
    """While a run writes to a folder, another run into it stops at once with exit 2 and
    names the holder; the first run is not disturbed. Afterwards the folder is free."""
    full = run(with_output(LONG_CAPSTAN, "full", output="vtk_every = 0"), tmp_path)
    assert full.returncode == 0, full.stderr
    first = start(with_output(LONG_CAPSTAN, "out", output="vtk_every = 0"), tmp_path)
    try:
        wait_for_step(first, 20)
        for text in (with_output(VNET, "out"),
                     with_output(VNET, "out", control="restart = .true.")):
            second = run(text, tmp_path)
            assert second.returncode == 2, second.stderr
            assert ("yarnfort: error (output): &output: folder 'out' is in use by another "
                    f"yarnfort run (pid {first.pid} host ") in second.stderr
        rest = first.stderr.read()
        assert first.wait(timeout=TIMEOUT) == 0, rest
    finally:
        with contextlib.suppress(ProcessLookupError):
            first.kill()
        first.stderr.close()
    compare_curves(read_rows(tmp_path / "full"), read_rows(tmp_path / "out"))
    after = run(with_output(VNET, "out"), tmp_path)
    assert after.returncode == 0, after.stderr


def test_killed_run_leaves_no_stale_lock(tmp_path):
    process = start(with_output(LONG_CAPSTAN, "out", output="vtk_every = 0"), tmp_path)
    wait_for_step(process, 10)
    process.kill()
    process.stderr.close()
    assert process.wait(timeout=TIMEOUT) == -signal.SIGKILL
    assert f"pid {process.pid} " in (tmp_path / "out" / ".yarnfort-lock").read_text()
    again = run(with_output(LONG_CAPSTAN, "out", control="restart = .true.",
                            output="vtk_every = 0"), tmp_path)
    assert again.returncode == 0, again.stderr


# ------------------------------------------------------------------ step numbers

#: Byte offsets of the fields of restart.dat (format version 4, see output/restart_file.f90;
#: the factors of the scenes' two default channels p_force and p_disp follow have_old).
OFFSET = {"n_nodes": 36, "n_elements": 40, "n_unknowns": 44, "n_passages": 48, "step": 52,
          "knot": 56, "time": 60, "next_step": 68, "previous_load": 76, "stepper": 84,
          "n_channels": 100, "load_old": 104, "time_old": 112, "have_old": 120, "p_force": 124,
          "p_disp": 132, "u": 140}
#: The file ends with a checksum (16 hex digits) of every byte before it.
CHECKSUM_LENGTH = 16


def checksum(data: bytes) -> bytes:
    """The restart file's checksum, written here from its description (two 32-bit
    FNV-1a-like hashes, primes 16777619 and 1000003, bases 2166136261 and 3735928559,
    over the bytes and then their count as a little-endian int64)."""
    state = [2166136261, 3735928559]
    primes = (16777619, 1000003)
    for byte in data + struct.pack("<q", len(data)):
        state = [((h ^ byte) * p) % 2**32 for h, p in zip(state, primes)]
    return f"{state[0]:08X}{state[1]:08X}".encode()


def patch(path: Path, field: str, fmt: str, value, restamp: bool = True) -> None:
    """Overwrite a field; with `restamp`, write the matching checksum too (a file that a
    faulty writer could have made whole), else leave the old one (damage after it was
    written)."""
    data = bytearray(path.read_bytes())
    struct.pack_into(fmt, data, OFFSET[field], value)
    if restamp:
        data[-CHECKSUM_LENGTH:] = checksum(bytes(data[:-CHECKSUM_LENGTH]))
    path.write_bytes(bytes(data))


def test_checksum_of_this_file_format(tmp_path):
    """The checksum written here from the format's description is the program's."""
    assert run(with_output(VNET, "out", control="max_steps = 2"), tmp_path).returncode == 0
    data = (tmp_path / "out" / "restart.dat").read_bytes()
    assert data[-CHECKSUM_LENGTH:] == checksum(data[:-CHECKSUM_LENGTH])


@pytest.mark.parametrize("field, fmt, value", [("u", "<d", 0.123), ("time", "<d", 0.3),
                                               ("step", "<i", 2)])
def test_damage_after_writing_is_refused_by_the_checksum(tmp_path, field, fmt, value):
    """A value changed in the file (any field, also one no other check could judge,
    such as a position) is refused: exit 2, the checksum named, nothing changed."""
    assert run(with_output(CAPSTAN, "out", control="max_steps = 4"),
               tmp_path).returncode == 0
    restart = tmp_path / "out" / "restart.dat"
    patch(restart, field, fmt, value, restamp=False)
    before = (tmp_path / "out" / "curve.csv").read_bytes()
    again = run(with_output(CAPSTAN, "out", control="restart = .true."), tmp_path)
    assert again.returncode == 2, again.stderr
    assert "checksum does not match" in again.stderr
    assert (tmp_path / "out" / "curve.csv").read_bytes() == before


def unpack(path: Path, field: str, fmt: str):
    return struct.unpack_from(fmt, path.read_bytes(), OFFSET[field])[0]


def test_state_names_past_step_99999(tmp_path):
    """A run that has reached step 123 456 (its restart file and curve renumbered, as a
    long run would leave them) goes on with state_123457.vtu, ...: no name overflows,
    every state keeps its own file, and states.pvd lists them in step order."""
    assert run(with_output(VNET, "out", control="max_steps = 3"), tmp_path).returncode == 0
    out = tmp_path / "out"
    big = 123_456
    assert unpack(out / "restart.dat", "step", "<i") == 3
    patch(out / "restart.dat", "step", "<i", big)
    lines = (out / "curve.csv").read_text().splitlines()
    lines[-1] = str(big) + lines[-1][1:]
    (out / "curve.csv").write_text("\n".join(lines) + "\n")
    proc = run(with_output(VNET, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 0, proc.stderr
    names = [name for name, _ in collection(out)]
    steps = [int(row[0]) for row in complete_rows(out)]
    assert steps[:5] == [0, 1, 2, big, big + 1] and steps[-1] > big + 2
    # The state written for step 3 (renumbered since) stays; then the new ones.
    expected = [f"state_{k:05d}.vtu" for k in (0, 1, 2, 3)] + [
        f"state_{k}.vtu" for k in range(big + 1, steps[-1] + 1)]
    assert names == expected
    assert sorted(p.name for p in out.glob("state_*.vtu")) == sorted(expected)
    assert len(read_state(out / expected[-1]).tension) == 2


# ------------------------------------------------------------------ restart integrity

def table_scene(tmp_path: Path) -> tuple[str, Path]:
    """The capstan scene with its yarn's force law from a table file in tmp_path."""
    table = tmp_path / "yarn.csv"
    table.write_text("strain,force\n0,0\n0.01,0.2\n0.02,0.5\n0.05,2.0\n0.2,12.0\n")
    text = CAPSTAN
    start_material = text.index("&material")
    end_material = text.index("/", start_material)
    text = (text[:start_material] + f"&material\n    name = 'yarn'\n    law = 'table'\n"
            f"    table_file = '{table}'\n" + text[end_material:])
    return text, table


def test_restart_with_a_changed_table_file_is_refused(tmp_path):
    text, table = table_scene(tmp_path)
    first = run(with_output(text, "out", control="max_steps = 5"), tmp_path)
    assert first.returncode == 0, first.stderr
    before = folder_content(tmp_path / "out")
    table.write_text(table.read_text().replace("0.02,0.5", "0.02,0.6"))
    proc = run(with_output(text, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 2
    assert "was written for another input" in proc.stderr
    assert folder_content(tmp_path / "out") == before
    # The same content again: the restart is accepted.
    table.write_text(table.read_text().replace("0.02,0.6", "0.02,0.5"))
    proc = run(with_output(text, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 0, proc.stderr


def geometry_scene(tmp_path: Path) -> str:
    """The V-net with its nodes and yarn in a geometry file tmp_path/vnet.geo."""
    (tmp_path / "vnet.geo").write_text("# the V-net\nnode 1 -1.0 0.0 0.0\n"
                                       "node 2 0.0 -0.2 0.0\nnode 3 1.0 0.0 0.0\n"
                                       "yarn yarn 1 1 2 3\n")
    text = VNET
    for group in ("&nodes", "&yarn"):
        first = text.index(group)
        text = text[:first] + text[text.index("/", first) + 1:]
    return text.replace("&support", "&geometry\n    file = 'vnet.geo'\n/\n\n&support", 1)


def test_restart_with_a_changed_geometry_file_is_refused(tmp_path):
    """Even a change that leaves the nodes and yarns as they are (a comment) counts:
    the fingerprint covers the file's content."""
    text = geometry_scene(tmp_path)
    first = run(with_output(text, "out", control="max_steps = 2"), tmp_path)
    assert first.returncode == 0, first.stderr
    with open(tmp_path / "vnet.geo", "a") as stream:
        stream.write("# a comment added later\n")
    proc = run(with_output(text, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 2
    assert "was written for another input" in proc.stderr


def corrupt(path: Path, field: str, how: str) -> None:
    if field in ("time", "next_step", "p_force", "p_disp", "previous_load", "load_old",
                 "time_old"):
        value = unpack(path, field, "<d")
        new = {"nan": float("nan"), "negative": -abs(value) - 1.0, "zero": 0.0, "tiny": 1e-300,
               "huge": 1e300, "shifted": value + 0.0123}[how]
        patch(path, field, "<d", new)
    elif field == "stepper":
        patch(path, field, "16s", b"elastic".ljust(16))
    elif field == "u":
        patch(path, field, "<d", float("inf"))
    else:
        value = unpack(path, field, "<i")
        patch(path, field, "<i", {"negative": -1, "zero": 0, "huge": 2**30,
                                  "plus_one": value + 1, "large": 10**6}[how])


@pytest.mark.parametrize("field, how, message", [
    ("step", "negative", "step -1 is negative"),
    ("knot", "zero", "knot 0 is not 2..3"),
    ("knot", "large", "knot 1000000 is not 2..3"),
    ("time", "negative", "is not on the load path (0.0 to 2.0)"),
    ("time", "nan", "time NaN is not on the load path"),
    ("time", "huge", "is not on the load path"),
    ("time", "shifted", "are not those of the path at its time"),
    ("next_step", "zero", "next step 0.0 is not in [min_step = 1.0e-6, max_step = 0.05]"),
    ("next_step", "tiny", "is not in [min_step"),
    ("next_step", "negative", "is not in [min_step"),
    ("next_step", "nan", "next step NaN is not in"),
    ("next_step", "huge", "is not in [min_step"),
    ("p_disp", "shifted", "are not those of the path at its time"),
    ("previous_load", "huge", "is not the sum of its load factors"),
    ("n_channels", "huge", "a size or flag field holds an impossible value"),
    ("n_channels", "zero", "a size or flag field holds an impossible value"),
    ("n_channels", "plus_one", "bytes do not fit the sizes it records"),
    ("load_old", "huge", "the load 1.0e300 of its previous step is not the sum of the load"),
    ("load_old", "shifted", "of its previous step is not the sum of the load factors"),
    ("time_old", "negative", "of its previous step is not on the load path before its time"),
    ("time_old", "shifted", "of its previous step is not the sum of the load factors at"),
    ("stepper", "", "its stepper 'elastic' is not 'friction'"),
    ("n_unknowns", "plus_one", "bytes do not fit the sizes it records"),
    ("n_unknowns", "huge", "bytes do not fit the sizes it records"),
    ("n_elements", "huge", "bytes do not fit the sizes it records"),
    ("n_passages", "negative", "a size or flag field holds an impossible value"),
    ("have_old", "large", "a size or flag field holds an impossible value"),
])
def test_damaged_restart_fields_are_refused(tmp_path, field, how, message):
    """Each field of the restart file is checked against the scene and its path before
    anything is solved or written; a huge size is refused before memory is asked for
    (the run gets 1 GB of address space, the field asks for 8 GB)."""
    assert run(with_output(CAPSTAN, "out", control="max_steps = 5"), tmp_path).returncode == 0
    corrupt(tmp_path / "out" / "restart.dat", field, how)
    before = folder_content(tmp_path / "out")
    proc = run(with_output(CAPSTAN, "out", control="restart = .true."), tmp_path,
               memory=1 << 30)
    assert proc.returncode == 2, proc.stderr
    assert "yarnfort: error (restart): &control restart: 'out/restart.dat'" in proc.stderr
    assert message in proc.stderr
    assert folder_content(tmp_path / "out") == before


def test_time_and_factors_changed_together_are_refused(tmp_path):
    """A restart file moved consistently to another time on the path still does not
    fit the curve row of its step."""
    assert run(with_output(CAPSTAN, "out", control="max_steps = 5"), tmp_path).returncode == 0
    path = tmp_path / "out" / "restart.dat"
    # Step 5 at t = 0.25 (p_disp = 0.25); move it to t = 0.3 with the path's factors.
    assert unpack(path, "time", "<d") == pytest.approx(0.25)
    patch(path, "time", "<d", 0.3)
    patch(path, "p_disp", "<d", 0.3)
    patch(path, "previous_load", "<d", 0.3)
    proc = run(with_output(CAPSTAN, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert ("the restart file's time 2.9999999999999999E-001 is not that of step 5 in "
            "'out/curve.csv' (2.5000000000000000E-001): the two files are not of the same "
            "run") in proc.stderr


def test_previous_time_and_load_changed_together_are_refused(tmp_path):
    """The previous step's time and load moved consistently along the path (the
    predictor would use them) still do not fit the curve row of the step before."""
    assert run(with_output(CAPSTAN, "out", control="max_steps = 5"), tmp_path).returncode == 0
    path = tmp_path / "out" / "restart.dat"
    # Step 4 at t = 0.2 (p_disp = 0.2); move it to t = 0.15 with the path's load there.
    assert unpack(path, "time_old", "<d") == pytest.approx(0.2)
    assert unpack(path, "load_old", "<d") == pytest.approx(0.2)
    patch(path, "time_old", "<d", 0.15)
    patch(path, "load_old", "<d", 0.15)
    proc = run(with_output(CAPSTAN, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert ("the restart file's previous time 1.4999999999999999E-001 is not that of step 4 "
            "in 'out/curve.csv' (2.0000000000000001E-001): the two files are not of the same "
            "run") in proc.stderr


@pytest.mark.parametrize("value", [float("inf"), float("nan")])
@pytest.mark.parametrize("scene, steps, field, message", [
    # The V-net has two position unknowns; the first one is damaged.
    (VNET, 3, "u", "a position or flow that is not a finite number"),
    # The load of the state before the last converged one is damaged.
    (CAPSTAN, 5, "load_old", "its previous state holds a value that is not a finite number"),
], ids=["position", "previous_load"])
def test_non_finite_value_in_restart_is_refused(tmp_path, value, scene, steps, field, message):
    control = f"max_steps = {steps}"
    assert run(with_output(scene, "out", control=control), tmp_path).returncode == 0
    patch(tmp_path / "out" / "restart.dat", field, "<d", value)
    proc = run(with_output(scene, "out", control="restart = .true."), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr


# ------------------------------------------------------------------ memory

def test_geometry_file_larger_than_memory(tmp_path):
    """A 3 GB geometry file (sparse: it takes no room) under a 1 GB address space: an
    error message with exit 2, no backtrace."""
    text = geometry_scene(tmp_path).replace("'vnet.geo'", "'big.geo'")
    with open(tmp_path / "big.geo", "wb") as stream:
        stream.truncate(3 << 30)
    proc = run(text, tmp_path, memory=1 << 30)
    assert proc.returncode == 2, proc.stderr
    assert ("yarnfort: error (input): &geometry: file 'big.geo' (3221225472 bytes) does not "
            "fit in memory") in proc.stderr


# ------------------------------------------------------------------ input.nml

def test_unwritable_input_echo_is_an_error(tmp_path):
    """input.nml cannot be written (a folder of that name is in the way): exit 2 and the
    reason, not a silent skip."""
    (tmp_path / "out" / "input.nml").mkdir(parents=True)
    (tmp_path / "out" / "input.nml" / "keep").write_text("x")
    proc = run(with_output(VNET, "out"), tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert ("yarnfort: error (output): cannot rename 'out/input.nml.tmp' to "
            "'out/input.nml'") in proc.stderr
    assert (tmp_path / "out" / "input.nml" / "keep").read_text() == "x"
