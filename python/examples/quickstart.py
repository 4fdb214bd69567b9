"""A capstan rig and a knit built in Python, run in process with progress bars, plotted."""
import numpy as np
import yarnfort
from yarnfort.plots import plot_fabric_hysteresis, plot_hysteresis, save_figure

rig = yarnfort.Scene("yarn over three pegs", output={"folder": "out/rig"})  # VTK states there
rig.add_material("yarn", "linear", stiffness=10.0)
rig.add_contact(("yarn", "yarn"), "adhesion", friction_coefficient=0.3, adhesion=0.05)
pegs = np.c_[np.cos(np.radians([150, 90, 30])), np.sin(np.radians([150, 90, 30])), [0, 0, 0]]
rig.nodes = np.vstack([[-1, -1, 0], pegs, [1, -1, 0], 0.8 * pegs])  # ids 1..8
for nodes in ([1, 2, 3, 4, 5], [2, 6], [3, 7], [4, 8]):  # the yarn, then three pegs
    rig.add_yarn("yarn", nodes)
rig.add_support("held", [1, 2, 3, 4, 6, 7, 8])
rig.add_support("pull", [5], displacement=[0, -0.3, 0])
rig.path = yarnfort.LoadPath(time=[0, 1, 2], p_disp=[0, 1, 0])  # pull, release

knit = yarnfort.Scene("knitted jersey", output={"folder": "out/jersey"})
knit.add_material("knit", "linear", stiffness=5.0, prestress=0.02)
knit.add_contact(("knit", "knit"), "adhesion", friction_coefficient=0.4, adhesion=0.015)
knit.fabric = yarnfort.Fabric("knit", cells=[2, 2], spacing=[1e-3, 0.8e-3], knit_material="knit")
knit.path = rig.path  # stretch to twice the length, release

rig_run, knit_run = rig.run(progress=True), knit.run(progress=True)
save_figure(plot_hysteresis(rig_run.curve, "pull"), "out/rig.png")
save_figure(plot_fabric_hysteresis(knit_run.curve), "out/jersey.png")
