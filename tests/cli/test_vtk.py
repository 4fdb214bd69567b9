# SPDX-License-Identifier: MIT
"""VTK states for ParaView, checked with two independent readers (meshio and VTK's own
XML reader): the yarns' file (point data displacement, position, contact state; cell
data tension, stretch, L0, yarn, material; only yarn elements, so that colouring by
tension shows yarn tensions), the gap-holders' block (drawn to the partner's image,
contact_force from the equilibrium of the leader node) and the periodic links' block
(a vertex at the leader's image), field data (time, step, load factors, a fabric's
strain), appended base64 binary by default and inline ASCII on request, each state's
multiblock file (read by VTK's XML multiblock reader, ParaView's own: its blocks by
name, tension only in the yarns' block) and states.pvd (the multiblock files and their
times)."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import f90nml
# The two readers are test dependencies (python/requirements.txt): missing, the tests
# fail rather than skip.
import meshio
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from yarnfort import read_curve, read_state

TOP = Path(__file__).resolve().parents[2]
INPUTS = TOP / "inputs"
TIMEOUT = 300

#: Kinds of links of a State.
GAP_HOLDER, PERIODIC = 1, 2
#: The solver's equilibrium: the force left at a node, relative to the forces there.
EQUILIBRIUM = 1e-6
#: Positions and lengths come from the same doubles: a length computed from positions
#: agrees with stretch * L0 to round-off of the length itself.
ROUND_OFF = 1e-12


def scene(name: str, folder: str, output: str = "") -> str:
    """An example scene with absolute table paths, writing to `folder`."""
    text = (INPUTS / f"{name}.nml").read_text()
    text = text.replace("'inputs/data/", f"'{INPUTS}/data/")
    lines = []
    for line in text.splitlines():
        if line.strip().startswith("folder ="):
            line = f"    folder = '{folder}'" + (f"\n    {output}" if output else "")
        lines.append(line)
    return "\n".join(lines) + "\n"


def vtk_read(path: Path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    assert reader.GetErrorCode() == 0, path
    return reader.GetOutput()


def vtk_arrays(grid) -> dict[str, np.ndarray]:
    """Every point, cell and field array of a grid read by VTK, by name."""
    arrays = {}
    for data in (grid.GetPointData(), grid.GetCellData()):
        for i in range(data.GetNumberOfArrays()):
            arrays[data.GetArrayName(i)] = vtk_to_numpy(data.GetArray(i))
    field = grid.GetFieldData()
    for i in range(field.GetNumberOfArrays()):
        arrays[field.GetArrayName(i)] = vtk_to_numpy(field.GetArray(i))
    return arrays


def meshio_arrays(mesh) -> dict[str, np.ndarray]:
    arrays = {name: np.asarray(v) for name, v in mesh.point_data.items()}
    arrays.update({name: np.concatenate(v) for name, v in mesh.cell_data.items()})
    arrays.update({name: np.asarray(v) for name, v in mesh.field_data.items()})
    return arrays


#: The blocks of a state's multiblock file by name, and the prefix of their files.
BLOCKS = {"yarns": "state_", "gap_holders": "holders_", "periodic_links": "links_",
          "passages": "passages_"}


def multiblock(folder: Path) -> list[tuple[str, float]]:
    """The files states.pvd lists (each state's multiblock file) and their times."""
    root = ET.parse(folder / "states.pvd").getroot()
    return [(d.get("file"), float(d.get("timestep"))) for d in root.iter("DataSet")]


def blocks(path: Path) -> dict[str, str]:
    """The blocks of a multiblock file: name -> file."""
    root = ET.parse(path).getroot()
    return {d.get("name"): d.get("file") for d in root.iter("DataSet")}


def collection(folder: Path) -> list[tuple[str, float]]:
    """The yarns' files of the states states.pvd lists, and their times."""
    return [(blocks(folder / name)["yarns"], time) for name, time in multiblock(folder)]


def check_parts(folder: Path, names: list[str]) -> None:
    """Every state states.pvd lists is a multiblock file of the yarns and the blocks
    `names`, their files those of the same step; VTK's XML multiblock reader (ParaView's)
    opens it with the blocks by name, each of the state's step and time, and only the
    yarns' block has `tension`."""
    for name, time in multiblock(folder):
        assert name.startswith("state_") and name.endswith(".vtm")
        step = name[len("state_"):-len(".vtm")]
        listed = blocks(folder / name)
        assert list(listed) == ["yarns"] + names
        assert listed == {block: BLOCKS[block] + step + ".vtu" for block in listed}
        reader = vtk.vtkXMLMultiBlockDataReader()
        reader.SetFileName(str(folder / name))
        reader.Update()
        assert reader.GetErrorCode() == 0, name
        data = reader.GetOutput()
        assert data.GetNumberOfBlocks() == len(listed)
        for i, block in enumerate(listed):
            assert data.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()) == block
            grid = data.GetBlock(i)
            assert grid.GetNumberOfCells() > 0, (name, block)
            assert grid.GetCellData().HasArray("tension") == (block == "yarns")
            assert grid.GetPointData().HasArray("tension") == 0
            # Every block is of the state's step and time (17 digits in states.pvd).
            field = grid.GetFieldData()
            assert field.GetArray("step").GetValue(0) == int(step)
            assert field.GetArray("time").GetValue(0) == time


def components(n_points: int, pairs: np.ndarray) -> int:
    """Connected parts of the graph of `pairs` over the nodes that any pair uses."""
    parent = list(range(n_points))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in pairs:
        parent[root(a)] = root(b)
    used = set(pairs.ravel())
    return len({root(i) for i in used})


def read_both(path: Path):
    """A file read with meshio and with VTK, which must give the same arrays: the meshio
    mesh, the VTK grid and the arrays by name."""
    mesh = meshio.read(path)
    grid = vtk_read(path)
    a, b = meshio_arrays(mesh), vtk_arrays(grid)
    assert set(a) == set(b)
    for name in a:
        np.testing.assert_array_equal(a[name].ravel(), b[name].ravel(), err_msg=name)
    return mesh, grid, b


def check_state(path: Path, initial: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Read a state with both readers, check they agree with each other and with the
    geometry of the file (displacement from `initial`, lengths); return the arrays."""
    mesh, grid, b = read_both(path)
    points = vtk_to_numpy(grid.GetPoints().GetData())
    np.testing.assert_array_equal(points, mesh.points)
    assert grid.GetNumberOfCells() == sum(len(c.data) for c in mesh.cells)
    assert {c.type for c in mesh.cells} == {"line"}
    np.testing.assert_array_equal(b["position"], points)
    if initial is not None:
        # The subtraction was made once in the program: equal to round-off.
        np.testing.assert_allclose(b["displacement"], points - initial, rtol=0,
                                   atol=ROUND_OFF * np.abs(points).max())
    pairs = np.concatenate([c.data for c in mesh.cells])
    length = np.linalg.norm(points[pairs[:, 1]] - points[pairs[:, 0]], axis=1)
    scale = length.max()
    np.testing.assert_allclose(b["stretch"] * b["L0"], length, rtol=0, atol=ROUND_OFF * scale)
    b["pairs"] = pairs
    b["points"] = points
    return b


def test_capstan_states_read_by_meshio_and_vtk(run_yarnfort, tmp_path):
    run = run_yarnfort(scene("capstan", "out"), timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    curve = read_curve(out)
    listed = collection(out)
    assert [name for name, _ in listed] == [f"state_{k:05d}.vtu" for k in range(len(listed))]
    np.testing.assert_array_equal([t for _, t in listed], curve["time"])
    initial = np.reshape(f90nml.read(INPUTS / "capstan.nml")["nodes"]["xyz"], (-1, 3))
    for k, (name, time) in enumerate(listed):
        text = (out / name).read_text()
        assert 'format="appended"' in text and 'encoding="base64"' in text
        arrays = check_state(out / name, initial)
        assert arrays["time"][0] == time and arrays["step"][0] == k
        assert arrays["p_disp"][0] == curve["p_disp"][k]
        assert "kind" not in arrays
        # The capstan scene: yarn 1 (material 1, 'yarn', 4 elements) over three pegs,
        # each held by a yarn of material 2 ('peg', 1 element).
        np.testing.assert_array_equal(arrays["yarn"], [1, 1, 1, 1, 2, 3, 4])
        np.testing.assert_array_equal(arrays["material"], [1, 1, 1, 1, 2, 2, 2])
        # Contact state per node: 0 (no passage), 1 (all stick), 2 (a passage slips);
        # the nodes with a slipping passage are at most the slipping passages.
        state = arrays["contact_state"]
        assert set(state) <= {0, 1, 2} and np.count_nonzero(state) == 3
        assert np.count_nonzero(state == 2) <= curve["slipping"][k]
        assert (np.count_nonzero(state == 2) > 0) == (curve["slipping"][k] > 0)
        # The yarn package reads the same values as VTK.
        own = read_state(out / name)
        np.testing.assert_array_equal(own.tension, arrays["tension"])
        np.testing.assert_array_equal(own.position, arrays["points"])


def test_ascii_states_hold_the_same_values(run_yarnfort, tmp_path):
    assert run_yarnfort(scene("capstan", "binary"), timeout=TIMEOUT).returncode == 0
    run = run_yarnfort(scene("capstan", "ascii", "vtk_format = 'ascii'"), timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr
    assert "vtk_format = 'ascii'" in (tmp_path / "ascii" / "input.nml").read_text()
    names = [name for name, _ in collection(tmp_path / "binary")]
    assert names == [name for name, _ in collection(tmp_path / "ascii")]
    initial = np.reshape(f90nml.read(INPUTS / "capstan.nml")["nodes"]["xyz"], (-1, 3))
    for name in (names[0], names[len(names) // 2], names[-1]):
        text = (tmp_path / "ascii" / name).read_text()
        assert 'format="appended"' not in text and 'format="ascii"' in text
        a = check_state(tmp_path / "ascii" / name, initial)
        b = check_state(tmp_path / "binary" / name, initial)
        # 17 significant digits read back to the same doubles.
        for key in b:
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)
        np.testing.assert_array_equal(read_state(tmp_path / "ascii" / name).tension,
                                      b["tension"])


def test_unknown_vtk_format_is_refused(run_yarnfort, tmp_path):
    run = run_yarnfort(scene("capstan", "out", "vtk_format = 'hdf5'"), timeout=TIMEOUT)
    assert run.returncode == 2
    assert "&output: vtk_format = 'hdf5' is unknown (use binary, ascii)" in run.stderr
    assert not (tmp_path / "out").exists()


def element_pulls(arrays: dict[str, np.ndarray]) -> np.ndarray:
    """The force of the yarn elements on each node (n_nodes, 3), N, from the yarns'
    file: tension along each element, towards its other end."""
    points, pairs = arrays["points"], arrays["pairs"]
    direction = points[pairs[:, 1]] - points[pairs[:, 0]]
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    pull = arrays["tension"][:, None] * direction
    force = np.zeros_like(points)
    np.add.at(force, pairs[:, 0], pull)
    np.add.at(force, pairs[:, 1], -pull)
    return force


def check_holders(path: Path, arrays: dict[str, np.ndarray], free: np.ndarray) -> np.ndarray:
    """The gap-holders' block of a state against the yarns' file `arrays`: each line
    from its leader to its follower's image (follower minus period); its force is the
    one the leader's yarn takes (equilibrium of a leader in `free`: no support, load
    or other link), contact_force its component along the line. Returns the block's
    arrays and the (leader, follower) pairs (from 0)."""
    mesh, _, b = read_both(path)
    assert {c.type for c in mesh.cells} == {"line"}
    leader, follower = b["leader"] - 1, b["follower"] - 1
    points = arrays["points"]
    ends = mesh.points[np.concatenate([c.data for c in mesh.cells])]
    np.testing.assert_array_equal(ends[:, 0], points[leader])
    scale = np.abs(points).max()
    np.testing.assert_allclose(ends[:, 1], points[follower] - b["period"], rtol=0,
                               atol=ROUND_OFF * scale)
    line = ends[:, 1] - ends[:, 0]
    np.testing.assert_allclose(b["stretch"] * b["L0"], np.linalg.norm(line, axis=1),
                               rtol=0, atol=ROUND_OFF * scale)
    pulls = element_pulls(arrays)
    check = np.isin(leader, free)
    assert np.count_nonzero(check) > 0
    # The leader is in equilibrium: its yarn pulls with what the holder pushes it with,
    # which is minus the force on the follower.
    force_scale = np.abs(arrays["tension"]).max()
    np.testing.assert_allclose(b["force"][check], pulls[leader[check]], rtol=0,
                               atol=EQUILIBRIUM * force_scale)
    unit = line / np.linalg.norm(line, axis=1)[:, None]
    np.testing.assert_allclose(b["contact_force"], np.sum(b["force"] * unit, axis=1),
                               rtol=0, atol=ROUND_OFF * force_scale)
    b["pairs"] = np.column_stack([leader, follower])
    return b


def test_belt_is_connected_by_its_gap_holders(run_yarnfort, tmp_path):
    """The twill belt: gap-holders are a block of their own and join warp and weft into
    one net; their stretch is the gap factor of the path (belt.nml's table); their
    contact force balances the leader's yarn and presses the yarns together."""
    run = run_yarnfort(scene("belt", "out"), timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    curve = read_curve(out)
    listed = collection(out)
    check_parts(out, ["gap_holders", "passages"])
    first = check_state(out / listed[0][0])
    initial = first["points"] - first["displacement"]
    for name, _ in (listed[0], listed[len(listed) // 2], listed[-1]):
        # Every state's displacement is from the same initial (generated) geometry.
        arrays = check_state(out / name, initial)
        n_points = len(arrays["points"])
        holders = check_holders(out / ("holders_" + name[len("state_"):]), arrays,
                                free=np.arange(n_points))
        # 12 weft and 8 warp yarns: 20 parts without the gap-holders, one with them.
        assert components(n_points, arrays["pairs"]) == 20
        assert components(n_points, np.concatenate([arrays["pairs"],
                                                    holders["pairs"]])) == 1
        assert set(arrays["yarn"]) == set(range(1, 21))
        p_disp = arrays["p_disp"][0]
        factor = np.interp(p_disp, [0.0, 0.5, 1.0], [1.0, 0.8, 0.7])
        np.testing.assert_allclose(holders["stretch"], factor, rtol=ROUND_OFF * 1e3)
        # The crimped, tensioned yarns press on each other: no holder pulls.
        assert np.all(holders["contact_force"] > 0)
        # The fabric's strain and force per width, as in curve.csv.
        step = int(arrays["step"][0])
        assert arrays["strain"][0] == curve["strain"][step]
        assert arrays["force_per_width"][0] == curve["force_per_width"][step]
        # read_state gives the same links.
        own = read_state(out / name)
        np.testing.assert_array_equal(own.links, holders["pairs"])
        np.testing.assert_array_equal(own.link_data["contact_force"],
                                      holders["contact_force"])


def test_knit_cell_has_periodic_links(run_yarnfort, tmp_path):
    """The knit cell: its periodic links are vertices at the leader's image (the
    follower, leader + period), never lines along the yarn they continue."""
    run = run_yarnfort(scene("knit", "out"), timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out"
    listed = collection(out)
    curve = read_curve(out)
    check_parts(out, ["gap_holders", "periodic_links", "passages"])
    first = check_state(out / listed[0][0])
    name = listed[len(listed) // 4][0]
    arrays = check_state(out / name, first["points"] - first["displacement"])
    suffix = name[len("state_"):]
    points = arrays["points"]
    links = meshio.read(out / ("links_" + suffix))
    assert {c.type for c in links.cells} == {"vertex"}
    data = meshio_arrays(links)
    leader, follower = data["leader"] - 1, data["follower"] - 1
    np.testing.assert_array_equal(links.points, points[follower])
    np.testing.assert_allclose(points[follower] - points[leader], data["period"], rtol=0,
                               atol=ROUND_OFF * np.abs(points).max())
    holders = check_holders(out / ("holders_" + suffix), arrays,
                            free=np.setdiff1d(np.arange(len(points)),
                                              np.concatenate([leader, follower])))
    pairs = np.concatenate([arrays["pairs"], holders["pairs"],
                            np.column_stack([leader, follower])])
    assert components(len(points), pairs) == 1
    step = int(arrays["step"][0])
    assert arrays["strain"][0] == curve["strain"][step]
    assert np.count_nonzero(arrays["contact_state"]) > 0


def test_states_pvd_of_a_long_path_lists_every_state(run_yarnfort, tmp_path):
    """states.pvd at the end of a long path lists every state, in step order, with its
    time, and nothing else. A two-element yarn pulled in 512 equal steps (exact in
    binary: step k ends at pseudo-time k / 512), a state every 3 steps, in two pieces:
    301 steps (the last one, not due, is written at the stop), then a restart to the end
    (the last step, 512, is written too). Past 100 states the file is rewritten only
    when it lags; the end and the restart write it whole."""
    steps, every, first = 512, 3, 301
    text = f"""&material name = 'yarn', law = 'linear', stiffness = 10.0 /
&nodes xyz = 0 0 0, 0.5 0 0, 1 0 0 /
&yarn material = 'yarn', nodes = 1, 2, 3 /
&support name = 'a', nodes = 1 /
&support name = 'b', nodes = 3, displacement = 0.1 0 0 /
&support name = 'm', nodes = 2, fix = 'yz' /
&path time = 0 1, p_disp = 0 1 /
&solver max_step = {1 / steps}, initial_step = {1 / steps} /
&output folder = 'out', vtk_every = {every}, progress = .false. /
"""
    out = tmp_path / "out"
    # Path length 1: times agree with k / steps to the round-off of a sum of steps.
    tolerance = steps * np.finfo(float).eps

    def check(expected_steps: list[int]) -> None:
        listed = collection(out)
        names = [f"state_{k:05d}.vtu" for k in expected_steps]
        assert [name for name, _ in listed] == names
        np.testing.assert_allclose([t for _, t in listed], np.array(expected_steps) / steps,
                                   rtol=0, atol=tolerance)
        assert sorted(p.name for p in out.glob("state_*.vtu")) == names
        assert sorted(p.name for p in out.glob("state_*.vtm")) == [
            name[:-len(".vtu")] + ".vtm" for name in names]
        for name in names:
            assert (out / name).read_bytes().endswith(b"</VTKFile>\n"), name

    run = run_yarnfort(text.replace("&material", f"&control max_steps = {first} /\n"
                                                 "&material", 1), timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr
    check(list(range(0, first, every)) + [first])
    run = run_yarnfort(text.replace("&material", "&control restart = .true. /\n&material", 1),
                       timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr
    check(list(range(0, first, every)) + [first] + list(range(first + 2, steps, every))
          + [steps])
    assert len(read_curve(out)["time"]) == steps + 1
