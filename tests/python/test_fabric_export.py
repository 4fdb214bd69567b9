# SPDX-License-Identifier: MIT
"""`python -m yarnfort export-fabric` (issue 40): the effective curves of a periodic knit
cell written for Abaqus (*FABRIC), LS-DYNA (*DEFINE_CURVE) and as CSV, read back here by
simple line parsers of their own (not the writer's code), converted back to N/m by hand
and compared with the run's curve.csv at every written point.

The knit cell is stretched along the courses on the path p_disp 0 -> 0.5 -> 0 -> 1 -> 0
-> 0.6 -> 0 (strain = p_disp). By the path alone (not by the exporter's rules): the
primary loading is time [0, 1] and the part of [2, 3] where the strain exceeds 0.5; the
unloadings from the primary peaks are time [1, 2] (from 0.5) and [3, 4] (from 1.0); the
release from 0.6 follows a reloading and is not from the primary curve. A second run of
the same cell (strain 0.6 at p_disp = 1, loaded and released once) stands in as
component 2, read through the uniaxial columns (``uniaxial=True``: every periodic run
now also has the membrane columns, in which this run's e22 does not grow)."""
from __future__ import annotations

import csv
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import yarnfort
from yarnfort import FabricExportError, export_fabric, read_curve

TOP = Path(__file__).resolve().parents[2]
#: Thickness of the test fabric and its value in mm and m.
THICKNESS_MM = 0.6
THICKNESS_M = 0.6e-3
#: Written values carry 13 significant digits: read back they equal the run's to this.
WRITTEN = 1e-11

KNIT = """
&material name = 'knit', law = 'table', table_file = 'inputs/data/knit_yarn.csv',
          prestress = 0.02 /
&material name = 'inlay', law = 'table', table_file = 'inputs/data/inlay_yarn.csv',
          prestress = 0.02 /
&contact materials = 'knit', 'knit', law = 'adhesion', friction_coefficient = 0.4,
         adhesion = 0.015 /
&contact materials = 'knit', 'inlay', law = 'adhesion', friction_coefficient = 0.4,
         adhesion = 0.015 /
&fabric kind = 'knit', cells = 2, 2, spacing = 1.0e-3, 0.8e-3, boundary = '{boundary}',
        strain = {strain}, knit_material = 'knit', inlay_material = 'inlay', gap = 0.3e-3 /
&path time = {time}, p_disp = {p_disp} /
&solver max_step = 0.1 /
&output folder = 'out/{name}' /
"""


#: A periodic 2/2 twill with friction, sheared to 0.4 and released: its crossings slide
#: and the shear in the yarns' frame is not zero (inputs/REFERENCE.md, Shear).
TWILL = """
&material name = 'warp', law = 'table', table_file = 'inputs/data/warp_yarn.csv',
          prestress = 0.02 /
&material name = 'weft', law = 'table', table_file = 'inputs/data/weft_yarn.csv',
          prestress = 0.02 /
&contact materials = 'warp', 'weft', law = 'adhesion', friction_coefficient = 0.3,
         adhesion = 0.01 /
&fabric kind = 'twill', cells = 4, 4, spacing = 1.0e-3, 0.5e-3, boundary = 'periodic',
        strain = 0.0, shear = 0.4, warp_material = 'warp', weft_material = 'weft',
        gap = 0.2e-3 /
&path time = 0, 1, 2, p_disp = 0, 1, 0 /
&solver max_step = 0.05 /
&output folder = 'out/{name}' /
"""


def _run(where: Path, name: str, *, strain: float = 0.0, time: str = "", p_disp: str = "",
         boundary: str = "periodic", template: str = KNIT, shear: float = 0.0,
         extra: str = "") -> Path:
    text = template.format(boundary=boundary, strain=strain, time=time, p_disp=p_disp,
                           name=name)
    if shear:
        text = text.replace("gap = 0.3e-3 /", f"gap = 0.3e-3, shear = {shear} /")
    if extra:
        text = text.replace("gap = 0.3e-3 /", f"gap = 0.3e-3, {extra} /")
    done = subprocess.run([str(yarnfort.program_path())], input=text, capture_output=True,
                          text=True, cwd=where, timeout=600)
    assert done.returncode == 0, done.stderr
    return where / "out" / name


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Path]:
    where = tmp_path_factory.mktemp("export")
    shutil.copytree(TOP / "inputs" / "data", where / "inputs" / "data")
    return {
        "partial": _run(where, "partial", strain=0.6, time="0, 1, 2", p_disp="0, 1, 0.5"),
        "cycles": _run(where, "cycles", strain=1.0, time="0, 1, 2, 3, 4, 5, 6",
                       p_disp="0, 0.5, 0, 1, 0, 0.6, 0"),
        "other": _run(where, "other", strain=0.6, time="0, 1, 2", p_disp="0, 1, 0"),
        "loading_only": _run(where, "loading_only", strain=0.3, time="0, 1",
                             p_disp="0, 1"),
        "twill_shear": _run(where, "twill_shear", template=TWILL),
        "knit_shear": _run(where, "knit_shear", strain=0.0, time="0, 1, 2",
                           p_disp="0, 1, 0", shear=0.4),
        # n22 held at 20 N/m: the cell narrows as it is stretched (knit_biaxial).
        "narrowing": _run(where, "narrowing", strain=0.6, time="0, 1, 2", p_disp="0, 1, 0",
                          extra="lateral_control = 'force', lateral_force = 20.0"),
    }


# -- what the run says, by the path ----------------------------------------------------

def segments(folder: Path) -> dict[str, list[np.ndarray]]:
    """Rows (strain, N/m) of the primary loading and of each unloading, from the path."""
    curve = read_curve(folder)
    t, e, n = curve["time"], curve["strain"], curve["force_per_width"]
    if folder.name == "cycles":
        primary = (t <= 1) | ((t >= 2) & (t <= 3) & (e > 0.5 + 1e-9))
        unloading = [(t >= 1) & (t <= 2), (t >= 3) & (t <= 4)]
    else:
        primary, unloading = t <= 1, [(t >= 1) & (t <= 2)]
    return {"loading": [np.column_stack([e[primary], n[primary]])],
            "unloading": [np.column_stack([e[m], n[m]]) for m in unloading]}


def assert_points_match(points: np.ndarray, expected: np.ndarray) -> None:
    """Every written (strain, N/m) point is a row of the run, and every row is written."""
    scale = np.abs(expected[:, 1]).max()    # the run's own force scale
    assert len(points) == len(expected)
    written = points[np.lexsort((points[:, 1], points[:, 0]))]
    rows = expected[np.lexsort((expected[:, 1], expected[:, 0]))]
    np.testing.assert_allclose(written[:, 0], rows[:, 0], rtol=0,
                               atol=WRITTEN * max(1.0, np.abs(rows[:, 0]).max()))
    np.testing.assert_allclose(written[:, 1], rows[:, 1], rtol=0, atol=WRITTEN * scale)


# -- readers of the written files (independent of the writer) --------------------------

#: What the Keywords Guide (6.14, *LOADING DATA and *UNLOADING DATA, "... uniaxial tests of
#: fabric materials") documents and the reader below checks: the five unloading
#: definitions; TYPE=DAMAGE and TYPE=PERMANENT DEFORMATION only with DIRECTION; a
#: nonelastic loading needs unloading data; a data line's first line holds the two
#: values, the temperature and up to five field variables (8 entries; more lines only
#: with DEPENDENCIES > 5); the data lines are repeated for every point of every curve.
UNLOADING_DEFINITIONS = {"COMBINED", "EXPONENTIAL", "INTERPOLATED CURVE", "QUADRATIC",
                         "SHIFTED CURVE"}
FIRST_LINE_ENTRIES = 8


def read_abaqus(path: Path) -> dict[str, dict[str, list[np.ndarray]]]:
    """{component: {'loading': [points], 'unloading': [points, ...]}} of a *FABRIC block,
    as written. The documented rules (above) are asserted; the rest is this writer's
    layout, not found in the manual pages read (docs/fabric_export.md): a data line's
    first two entries are stress, strain, and the unloading curves split where the
    strain drops."""
    out: dict[str, dict[str, list]] = {}
    component = block = loading_type = None
    keywords = []
    for line in path.read_text().splitlines():
        if line.startswith("**") or not line.strip():
            continue
        if line.startswith("*"):
            words = [w.strip().upper() for w in line[1:].split(",")]
            keywords.append(words[0])
            options = dict(w.split("=", 1) for w in words[1:] if "=" in w)
            if words[0] == "UNIAXIAL":
                assert loading_type in (None, "ELASTIC") or block == "unloading", \
                    "nonelastic loading data without unloading data"
                assert keywords[-2] in ("FABRIC", "LOADING DATA", "UNLOADING DATA")
                component = options["COMPONENT"]
                assert component in ("1", "2", "SHEAR")
                out[component] = {"loading": [], "unloading": []}
                block = loading_type = None
            elif words[0] in ("LOADING DATA", "UNLOADING DATA"):
                assert keywords[-2] == ("UNIAXIAL" if words[0] == "LOADING DATA"
                                        else "LOADING DATA")
                block = "loading" if words[0] == "LOADING DATA" else "unloading"
                if block == "unloading":
                    assert options["DEFINITION"] in UNLOADING_DEFINITIONS
                    assert options["DEFINITION"] == "INTERPOLATED CURVE"
                else:
                    loading_type = options.get("TYPE", "ELASTIC")
                    if loading_type != "ELASTIC":
                        assert "DIRECTION" in options
                    assert options["DIRECTION"] == "TENSION"
                    assert options["REGULARIZE"] == "OFF"
            else:
                block = None
            continue
        entries = line.split(",")
        assert 2 <= len(entries) <= FIRST_LINE_ENTRIES, line
        stress, strain = (float(v) for v in entries[:2])
        curves = out[component][block]
        if not curves or (block == "unloading" and strain < curves[-1][-1][1]):
            curves.append([])
        curves[-1].append((stress, strain))
    assert loading_type in (None, "ELASTIC") or block == "unloading"
    assert keywords[:2] == ["MATERIAL", "FABRIC"]
    return {c: {b: [np.array(p) for p in v] for b, v in d.items()} for c, d in out.items()}


def read_lsdyna(path: Path) -> list[tuple[int, str, np.ndarray]]:
    """(LCID, title, points as written) of each *DEFINE_CURVE_TITLE, fixed-width fields."""
    lines = [line for line in path.read_text().splitlines() if not line.startswith("$")]
    assert lines[0] == "*KEYWORD" and lines[-1] == "*END"
    curves = []
    k = 1
    while k < len(lines) - 1:
        assert lines[k] == "*DEFINE_CURVE_TITLE", lines[k]
        title, card = lines[k + 1], lines[k + 2]
        assert len(card) <= 80
        lcid, sidr = int(card[0:10]), int(card[10:20])
        sfa, sfo, offa, offo = (float(card[i:i + 10]) for i in range(20, 60, 10))
        assert (sidr, sfa, sfo, offa, offo) == (0, 1.0, 1.0, 0.0, 0.0)
        k += 3
        points = []
        while not lines[k].startswith("*"):
            assert len(lines[k]) == 40, repr(lines[k])
            points.append((float(lines[k][0:20]), float(lines[k][20:40])))
            k += 1
        curves.append((lcid, title, np.array(points)))
    return curves


# -- tests -------------------------------------------------------------------------------

def test_abaqus_round_trip(runs, tmp_path):
    out = export_fabric({"1": runs["cycles"], "2": runs["other"]}, tmp_path / "knit.inp",
                        thickness=f"{THICKNESS_MM}mm", units="N,mm", uniaxial=True)
    written = read_abaqus(out)
    assert sorted(written) == ["1", "2"]
    for component, folder in (("1", runs["cycles"]), ("2", runs["other"])):
        expected = segments(folder)
        got = written[component]
        assert len(got["loading"]) == 1
        assert len(got["unloading"]) == len(expected["unloading"])
        for branch in ("loading", "unloading"):
            for points, rows in zip(got[branch], expected[branch]):
                # MPa = N/mm^2 -> Pa (x 1e6), times the thickness (m) -> N/m.
                assert_points_match(np.column_stack([points[:, 1],
                                                     points[:, 0] * 1e6 * THICKNESS_M]),
                                    rows)
                assert np.all(np.diff(points[:, 1]) >= 0)  # strain ascending
    peaks = [curve[:, 1].max() for curve in written["1"]["unloading"]]
    np.testing.assert_allclose(peaks, [0.5, 1.0], rtol=1e-12)


def test_lsdyna_round_trip(runs, tmp_path):
    out = export_fabric([("1", runs["cycles"])], tmp_path / "knit.k", format="lsdyna",
                        thickness="0.06cm", units="kN,m", first_curve_id=100)
    curves = read_lsdyna(out)
    assert [c[0] for c in curves] == [100, 101, 102]
    assert "loading" in curves[0][1] and all("unloading" in c[1] for c in curves[1:])
    expected = segments(runs["cycles"])
    for (_, _, points), rows in zip(curves, expected["loading"] + expected["unloading"]):
        assert np.all(np.diff(points[:, 0]) >= 0)  # abscissae ascending
        # kN/m^2 -> N/m^2 (x 1e3), times the thickness (0.06 cm = 6e-4 m) -> N/m.
        assert_points_match(np.column_stack([points[:, 0], points[:, 1] * 1e3 * 6e-4]),
                            rows)


def test_csv_round_trip(runs, tmp_path):
    out = export_fabric({"1": runs["cycles"]}, tmp_path / "knit.csv", format="csv",
                        units="N,mm")
    with open(out, newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert "stress (N/mm^2)" not in rows[0]         # no thickness: no stress column
    expected = segments(runs["cycles"])
    for branch in ("loading", "unloading"):
        curves = sorted({int(r["curve"]) for r in rows if r["branch"] == branch})
        assert len(curves) == len(expected[branch])
        for curve, want in zip(curves, expected[branch]):
            mine = [r for r in rows if r["branch"] == branch and int(r["curve"]) == curve]
            points = np.array([(float(r["strain"]), float(r["membrane_force (N/mm)"]) * 1e3)
                               for r in mine])        # N/mm -> N/m
            assert_points_match(points, want)


def test_inch_units(runs, tmp_path):
    """lbf and in (psi): the conversion by hand with the exact pound-force and inch."""
    out = export_fabric({"1": runs["other"]}, tmp_path / "knit.csv", format="csv",
                        thickness="0.025in", units="lbf,in")
    with open(out, newline="") as stream:
        rows = list(csv.DictReader(stream))
    psi = np.array([float(r["stress (lbf/in^2)"]) for r in rows])
    width = np.array([float(r["membrane_force (lbf/in)"]) for r in rows])
    n = psi * 4.4482216152605 / 0.0254 ** 2 * (0.025 * 0.0254)    # -> Pa -> N/m
    np.testing.assert_allclose(width * 4.4482216152605 / 0.0254, n, rtol=1e-11)
    expected = segments(runs["other"])
    assert_points_match(np.column_stack([[float(r["strain"]) for r in rows if
                                          r["branch"] == "loading"],
                                         n[[r["branch"] == "loading" for r in rows]]]),
                        expected["loading"][0])


def test_shear_and_missing_components(runs, tmp_path):
    # A periodic run has the gamma12 column, 0 without a shear channel: no shear curve.
    with pytest.raises(FabricExportError, match="component 12: gamma12 never grows"):
        export_fabric({"12": runs["cycles"]}, tmp_path / "a.inp", thickness="1mm")
    with pytest.raises(FabricExportError, match="cannot give component 12"):
        export_fabric({"12": runs["cycles"]}, tmp_path / "a.inp", thickness="1mm",
                      uniaxial=True)


def test_shear_round_trip(runs, tmp_path):
    """Component 12 of a sheared twill (friction, sliding): Abaqus COMPONENT=SHEAR and an
    LS-DYNA curve hold, at every step of the path's loading (time [0, 1]) and release
    ([1, 2]), gamma12 and the shear in the yarns' frame worked out here from curve.csv's
    n12, n22 and gamma12: tau = n12 cos(gamma12) - n22 sin(gamma12)."""
    folder = runs["twill_shear"]
    curve = read_curve(folder)
    t, gamma = np.asarray(curve["time"]), np.asarray(curve["gamma12"])
    tau = np.asarray(curve["n12"]) * np.cos(gamma) - np.asarray(curve["n22"]) * np.sin(gamma)
    # Not zero: sliding at the twill's crossings (a pin-jointed net would give 0).
    assert np.abs(tau).max() > 1e-5 * np.abs(curve["n22"]).max()
    expected = {"loading": [np.column_stack([gamma[t <= 1], tau[t <= 1]])],
                "unloading": [np.column_stack([gamma[t >= 1], tau[t >= 1]])]}
    written = read_abaqus(export_fabric({"12": folder}, tmp_path / "twill.inp",
                                        thickness="0.6mm", units="N,mm"))
    assert sorted(written) == ["SHEAR"]
    for branch in ("loading", "unloading"):
        (points,) = written["SHEAR"][branch]
        assert_points_match(np.column_stack([points[:, 1], points[:, 0] * 1e6 * THICKNESS_M]),
                            expected[branch][0])
    curves = read_lsdyna(export_fabric({"12": folder}, tmp_path / "twill.k", format="lsdyna",
                                       thickness="0.6mm", units="N,m"))
    for (_, _, points), rows in zip(curves, expected["loading"] + expected["unloading"]):
        assert_points_match(np.column_stack([points[:, 0], points[:, 1] * THICKNESS_M]),
                            rows)


def test_shear_without_stiffness_refused(runs, tmp_path):
    """The knit sheared: its crossings are pins, the shear in the yarns' frame is zero,
    and component 12 is refused with the mechanism named, nothing written."""
    with pytest.raises(FabricExportError, match="no shear stiffness.*crossings are pins"):
        export_fabric({"12": runs["knit_shear"]}, tmp_path / "k.inp", thickness="1mm")
    assert not (tmp_path / "k.inp").exists()


def test_no_unloading_refused_or_left_out(runs, tmp_path):
    target = tmp_path / "a.inp"
    with pytest.raises(FabricExportError, match="no unloading"):
        export_fabric({"1": runs["loading_only"]}, target, thickness="1mm")
    assert not target.exists()
    export_fabric({"1": runs["loading_only"]}, target, thickness="1mm", unloading=False)
    keywords = [line for line in target.read_text().splitlines()
                if line.startswith("*") and not line.startswith("**")]
    assert not any("UNLOADING" in k or "TYPE=DAMAGE" in k for k in keywords), keywords
    assert len(read_abaqus(target)["1"]["loading"][0]) == len(read_curve(
        runs["loading_only"]))


def test_not_a_periodic_cell(runs, tmp_path):
    clamped = tmp_path / "clamped"
    shutil.copytree(runs["other"], clamped)
    text = (clamped / "input.nml").read_text()
    (clamped / "input.nml").write_text(text.replace("'periodic'", "'clamped'"))
    with pytest.raises(FabricExportError, match="not a periodic cell"):
        export_fabric({"1": clamped}, tmp_path / "a.csv", format="csv")
    (clamped / "input.nml").write_text("&control title = 'no fabric' /\n")
    with pytest.raises(FabricExportError, match="not a periodic fabric cell"):
        export_fabric({"1": clamped}, tmp_path / "a.csv", format="csv")


@pytest.mark.parametrize("options, words", [
    ({"thickness": "0.6"}, "with its unit"),
    ({"thickness": "0.6N"}, "not a length unit"),
    ({"thickness": "-1mm"}, "positive"),
    ({"thickness": "1mm", "units": "mm,N"}, "force unit then its length unit"),
    ({"thickness": "1mm", "units": "N"}, "force unit then its length unit"),
    ({}, "--thickness"),
])
def test_bad_options(runs, tmp_path, options, words):
    with pytest.raises(FabricExportError, match=words):
        export_fabric({"1": runs["other"]}, tmp_path / "a.inp", **options)
    assert not (tmp_path / "a.inp").exists()


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "yarnfort", "export-fabric", *args],
                          capture_output=True, text=True, timeout=300)


def test_cli_writes_and_refuses_overwrite(runs, tmp_path):
    out = tmp_path / "knit.inp"
    args = [str(runs["cycles"]), str(runs["other"]), "--component", "1", "2",
            "--thickness", "0.6mm", "--units", "N,mm", "--uniaxial", "-o", str(out)]
    done = _cli(*args)
    assert done.returncode == 0, done.stderr
    first = out.read_text()
    assert read_abaqus(out).keys() == {"1", "2"}
    out.write_text("keep me\n")
    done = _cli(*args)
    assert done.returncode == 2 and "exists" in done.stderr
    assert out.read_text() == "keep me\n"
    done = _cli(*args, "--force")
    assert done.returncode == 0 and out.read_text() == first
    done = _cli(str(runs["cycles"]), "--component", "1", "2", "-o", str(tmp_path / "b.csv"),
                "--format", "csv", "--uniaxial")
    assert done.returncode == 2 and "only the uniaxial columns" in done.stderr
    done = _cli(str(runs["cycles"]), str(runs["other"]), "--component", "1",
                "-o", str(tmp_path / "c.csv"), "--format", "csv")
    assert done.returncode == 2 and "one --component per RUN" in done.stderr
    assert not list(tmp_path.glob("*.tmp")) and not list(tmp_path.glob(".*.tmp"))


def test_membrane_columns_give_all_components(runs, tmp_path):
    """A curve.csv with the membrane columns (as periodic runs write them once issue 40's
    biaxial part lands) gives components 1, 2 and 12 from one run, each from its own
    pair. The columns here are the knit run's, scaled by known factors, so that each
    component's points are told apart by hand."""
    folder = tmp_path / "membrane"
    shutil.copytree(runs["cycles"], folder)
    with open(folder / "curve.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    factors = {"e11": ("strain", 1.0), "n11": ("force_per_width", 1.0),
               "e22": ("strain", 0.5), "n22": ("force_per_width", 2.0),
               "gamma12": ("strain", 0.1), "n12": ("force_per_width", 0.3)}
    for row in rows:
        for name, (source, factor) in factors.items():
            row[name] = repr(factor * float(row[source]))
    with open(folder / "curve.csv", "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    out = tmp_path / "all.inp"
    done = _cli(str(folder), "--component", "1", "2", "12", "--thickness", "0.6mm",
                "--units", "N,mm", "-o", str(out))
    assert done.returncode == 0, done.stderr
    written = read_abaqus(out)
    assert sorted(written) == ["1", "2", "SHEAR"]
    expected = segments(runs["cycles"])
    for component, (e, n) in (("1", (1.0, 1.0)), ("2", (0.5, 2.0)), ("SHEAR", (0.1, 0.3))):
        for branch in ("loading", "unloading"):
            assert len(written[component][branch]) == len(expected[branch])
            for points, rows_ in zip(written[component][branch], expected[branch]):
                # Shear: the force in the yarns' frame, n12 cos(gamma12) - n22
                # sin(gamma12), with n12 = 0.3 f, n22 = 2 f, gamma12 = 0.1 strain.
                factor = (0.3 * np.cos(0.1 * points[:, 1] / e) - 2.0 * np.sin(
                    0.1 * points[:, 1] / e)) if component == "SHEAR" else n
                assert_points_match(np.column_stack([points[:, 1] / e,
                                                     points[:, 0] * 1e6 * THICKNESS_M
                                                     / factor]), rows_)
    # A cell turned by 90 degrees, given as component 2: its e22 does not grow, the
    # message points to --uniaxial, which reads its x direction (strain).
    for row in rows:
        row["e22"] = "0.0"
    with open(folder / "curve.csv", "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    with pytest.raises(FabricExportError, match="--uniaxial"):
        export_fabric({"2": folder}, tmp_path / "turned.csv", format="csv")
    export_fabric({"2": folder}, tmp_path / "turned.csv", format="csv", uniaxial=True)
    with open(tmp_path / "turned.csv", newline="") as stream:
        strains = [float(r["strain"]) for r in csv.DictReader(stream)]
    assert max(strains) == pytest.approx(1.0, rel=1e-12)   # the cell's x strain


def test_partial_release_refused_for_abaqus_only(runs, tmp_path):
    """A release to half the peak strain is an unloading curve for LS-DYNA and CSV, but
    has no place in the Abaqus layout written (each curve from the start strain up)."""
    with pytest.raises(FabricExportError, match="stops at strain 0.3"):
        export_fabric({"1": runs["partial"]}, tmp_path / "a.inp", thickness="1mm")
    assert not (tmp_path / "a.inp").exists()
    curves = read_lsdyna(export_fabric({"1": runs["partial"]}, tmp_path / "a.k",
                                       format="lsdyna", thickness="1mm"))
    assert len(curves) == 2
    np.testing.assert_allclose(curves[1][2][[0, -1], 0], [0.3, 0.6], rtol=1e-12)


def test_csv_names_the_force_it_holds(runs, tmp_path):
    """A cell that narrows (n22 held, e22 down to -0.4): component 1 is n11, per current
    width, not curve.csv's force_per_width, per undeformed width (n11 (1 + e22), 0.6 n11
    at the peak). The CSV's force column has a neutral name and every row names its
    source; --uniaxial gives force_per_width itself."""
    folder = runs["narrowing"]
    curve = read_curve(folder)
    row_of = {int(step): k for k, step in enumerate(curve["step"])}
    assert curve["e22"].min() < -0.3  # the two widths differ: the name matters here
    for uniaxial, source in ((False, "n11"), (True, "force_per_width")):
        out = export_fabric({"1": folder}, tmp_path / f"{source}.csv", format="csv",
                            units="N,m", uniaxial=uniaxial)
        with open(out, newline="") as stream:
            rows = list(csv.DictReader(stream))
        assert "force_per_width (N/m)" not in rows[0]
        assert {r["force_from"] for r in rows} == {source}
        k = np.array([row_of[int(r["step"])] for r in rows])
        force = np.array([float(r["membrane_force (N/m)"]) for r in rows])
        per_undeformed_width = force * (1.0 + curve["e22"][k]) if source == "n11" else force
        np.testing.assert_allclose(per_undeformed_width, curve["force_per_width"][k],
                                   rtol=1e-9)
    text = export_fabric({"1": folder}, tmp_path / "n.inp", thickness="0.6mm").read_text()
    assert "n11 at the first step" in text


def test_a_run_cut_short_is_exported_with_a_warning(runs, tmp_path):
    # Stopped after 6 steps of 0.1 (max_steps, as Ctrl-C or a failed step would): its
    # loading ends at strain 0.36 of the path's 0.6 and it has no unloading.
    where = runs["partial"].parents[1]
    cut = _run(where, "cut", strain=0.6, time="0, 1, 2", p_disp="0, 1, 0",
               template=KNIT + "&control max_steps = 6 /\n")
    with pytest.warns(RuntimeWarning, match=r"incomplete run: the curve ends at step 6,"
                      r" time 0\.6, the load path at 2"):
        curves = yarnfort.fabric_curves(cut, "1", uniaxial=True)
    assert curves.loading.strain[-1] == pytest.approx(0.6 * 0.6, rel=WRITTEN)
    done = _cli(str(cut), "--component", "1", "--uniaxial", "--format", "csv",
                "--no-unloading", "-o", str(tmp_path / "cut.csv"))
    assert done.returncode == 0 and "warning:" in done.stderr
    assert "incomplete run" in done.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a whole run: no warning
        yarnfort.fabric_curves(runs["other"], "1", uniaxial=True)
