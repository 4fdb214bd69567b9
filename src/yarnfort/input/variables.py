# SPDX-License-Identifier: MIT
"""The one description of the namelist input: every group and variable, in the order
they are read, echoed and documented. generate.py makes from it the config types, the
reader, the generic checks, the echo and the --help summary (Fortran, at build time)
and the variable tables of inputs/REFERENCE.md (checked by a test).

A group: name, kind (singleton or repeatable), one line of documentation, variables.
A variable: name, type (character, real, integer, logical), default; optional: length
(character), shape (a size or "list"), max (most entries of a list, a Fortran name),
unit, range (">= 0", "> 0", "(0, 1)", "[a, b]", "finite"), choices (allowed values,
case-folded), retired (values no longer offered, each with the advice its refusal
gives), lower (fold the value to lower case), adjust (drop leading blanks),
selects (the variable choosing the law whose parameters the others are), laws (the
values of the selecting variable that use this one: required for those, an error for
the others), presets (the value each named preset of the group's `preset` variable
gives it unless the input sets it), checked_by (checked by
another module, named here: range and choices are documentation only), default_doc
and type_doc (table text where the value alone does not say it), doc (the meaning).
"""
from __future__ import annotations

from descriptors import Group, Var

#: Both columns of the gap-factor curve of &fabric.
GAP_FACTOR = ('The gap factor as a piecewise-linear function of the displacement factor p_disp '
              "(constant beyond the end knots): the holders' length is gap * factor (paper "
              'Fig. 13b). `gap_factor_p_disp` increasing; factors at least `100 * epsilon` '
              '(about 2.2e-14): a smaller one collapses the holders to zero length.')
#: A name that other groups or columns refer to.
NAME_RULE = 'Required and unique. One word of letters, digits, `_`, `-`, `.`.'
#: The nodes of a named node set.
NODE_SET = 'At least one node id, each in 1..n_nodes, no repeats'
#: The optional long-format files of &output follow curve.csv.
LIKE_CURVE = ('Written, flushed and resumed on restart like `curve.csv` (a restart with it '
              'needs the file of the first run; one without it deletes the file).')



def law_parameter(name: str, unit: str, range: str, laws: list[str], doc: str,
                  **extra: object) -> Var:
    """A real parameter of the laws `laws` of the group's selecting variable, without a
    default: not set until the input gives it (required for those laws, an error for the
    others); every value given is checked as a value."""
    return Var(name, 'real', None, unit=unit, range=range, laws=laws,
               default_doc='not set', doc=doc, **extra)  # type: ignore[arg-type]


def node_set(doc: str) -> Var:
    """The `nodes` of a named node set (&support, &load, &obstacle, &ring)."""
    return Var('nodes', 'integer', None, shape='list', doc=f'{NODE_SET}{doc}')


def knot_list(name: str, unit: str, default_doc: str | None, doc: str) -> Var:
    """A list of &path given knot by knot: finite values."""
    return Var(name, 'real', None, shape='list', unit=unit, range='finite',
               default_doc=default_doc, doc=doc)


def fabric_vars(*variables: Var) -> list[Var]:
    """The variables of &fabric: checked by the fabric module (range and choices are
    documentation only)."""
    for var in variables:
        var.checked_by = 'fabric'
    return list(variables)


def fabric_material(name: str, default_doc: str, doc: str) -> Var:
    """A yarn type of &fabric: the name of a `&material`."""
    return Var(name, 'character', '', length='name_length', default_doc=default_doc, doc=doc)


def channel_var(group: str, scaled: str, default: str) -> Var:
    """The `channel` of &support or &load: the load channel that scales `scaled`."""
    return Var('channel', 'character', '', length='name_length',
               default_doc=f"`''` (`'{default}'`)",
               doc=f'The load channel whose factor scales `{scaled}`: a name of `&path '
                   f"channels`, or `'p_force'` / `'p_disp'` without them ('' is `'{default}'`). "
                   f'With `&path channels`, a {group} with a nonzero {scaled} must name one. '
                   'See *Load channels* below.')


def sliding_node_group(name: str, doc: str, name_doc: str, nodes_doc: str) -> Group:
    """&obstacle or &ring (nodes that yarns slide through): name_doc and nodes_doc end the
    docs of its variables `name` and `nodes`."""
    return Group(name, 'repeatable', doc, [
        Var('name', 'character', '', length='name_length',
            doc='Required and unique among `&obstacle`, `&ring` and `&support` names. One word '
                'of letters, digits, `_`, `-`, `.`. `&contact at` names it' + name_doc),
        node_set(', each passed through (not ended at) by every yarn that lists it. '
                 + nodes_doc),
    ])


GROUPS = [
    Group('control', 'singleton',
          'What the run is.', [
        Var('title', 'character', '', length=256, adjust=False,
            doc='Title of the run (kept in the scene and the echoed input).'),
        Var('check_only', 'logical', False,
            doc='Stop after reading and checking the input (no solve, no output).'),
        Var('restart', 'logical', False,
            doc='Continue from the restart file `restart.dat` of the `&output` folder, i.e. from '
                'the last converged step of an earlier run of this scene that was stopped, '
                'killed or failed, instead of starting at the first knot. See *Restart* below.'),
        Var('max_steps', 'integer', 0, range='>= 0',
            doc='Stop after this many converged load steps of this run (0: no limit), with every '
                'output and the restart file written (exit code 0). A run with `restart = '
                '.true.` goes on from there: long runs can be made in pieces.'),
    ]),
    Group('solver', 'singleton',
          'Nonlinear and linear solver settings, continuation step control and the friction '
          'scheme.', [
        # The presets' values (initial_step = max_step, residual_tolerance, scheme) come
        # from verification/speed_accuracy/presets.py (every scene of
        # tests/verification/test_defaults.py against its exact reference): at these steps
        # the error follows the tolerance, the step sets how finely the curve is drawn, and
        # the monolithic scheme was the faster one. Each is on the speed-accuracy front of
        # benchmarks/presets_front.py; 'fast' was dropped (docs/decisions.md, *Presets on
        # the speed-accuracy front*): refused with what to use instead.
        Var('preset', 'character', 'custom', length=16, lower=True,
            choices=['custom', 'balanced', 'accurate'],
            retired={'fast': 'it ran no faster than the defaults (inputs/REFERENCE.md, '
                             "*Presets*); leave preset out for the defaults, or use "
                             "'balanced' or 'accurate'"},
            doc='Named defaults for `initial_step`, `max_step`, `residual_tolerance` and '
                "`scheme`: `'balanced'` or `'accurate'` (case-insensitive), chosen "
                "from a speed-accuracy study; `'custom'` keeps the defaults of this table. A "
                'variable given in `&solver` overrides its preset value. See *Presets* below.'),
        Var('linear_solver', 'character', 'auto', length=16, lower=True,
            choices=['auto', 'umfpack', 'klu', 'cholmod', 'cholmod+klu', 'dense'],
            doc="Case-insensitive. `'cholmod+klu'` is CHOLMOD, switching to KLU for good if "
                "a matrix is not positive definite. `'auto'` picks from measurements "
                "(`benchmarks/run`): "
                "`'cholmod+klu'` for the elastic solves when `slack_stiffness > 0` (the tangent "
                'of taut strings is positive semi-definite and slack strings get the '
                "regularising spring's, see `slack_stiffness`), otherwise KLU up to 5e3 "
                'unknowns and UMFPACK above; the unsymmetric friction systems never use '
                'CHOLMOD: with stick flows eliminated, their reduced system goes to KLU, or to '
                "UMFPACK where KLU's analysis predicts 80 or more flops per factor nonzero "
                '(decided per pattern, `docs/decisions.md`).'),
        Var('residual_tolerance', 'real', 1e-10, unit='1', range='> 0',
            presets={'balanced': 1e-9, 'accurate': 1e-11},
            doc='Relative. Newton stops when every row meets \\|F_i\\| <= residual_tolerance * '
                'level_i + noise_i. For a node, level_i is the largest force that meets there '
                '(the tensions of its elements, its applied load), at least 1e-6 times the '
                "largest force of the scene; noise_i is the rounding of the residual's "
                'evaluation (8 eps (\\|T\\| + r dT/dlambda) per element, r = (\\|x1\\| + \\|x2\\| + '
                'l) / L0), which only matters for nearly inextensible yarns. A friction slip row '
                '(T_crit(T_lo) - T_hi, divided by w = max(1, dT_crit/dT_lo), frozen per Newton '
                "solve) is judged against the passage's larger tension / w; a stick row asks for "
                'the flow to residual_tolerance * mean element length. No material stiffness '
                'enters: a scene gives the same relative answer in any units and whatever the '
                'stiffness of a part that carries no load.'),
        Var('step_tolerance', 'real', 1e-14, unit='1', range='> 0',
            doc='Newton also stops when the scaled step is below this. The residual tolerance is '
                'then still checked: a small step alone never counts as convergence.'),
        Var('max_iterations', 'integer', 50, range='>= 1',
            doc='Newton iterations of each attempt of a solve (full steps, then line search; '
                'see `line_search`).'),
        Var('max_setup_calls', 'integer', 1, range='>= 1',
            doc='Newton iterations between Jacobian updates (1 = full Newton).'),
        Var('line_search', 'logical', True,
            doc='Globalisation. Every Newton solve first takes full Newton steps; with '
                "`.true.`, a solve that fails is repeated from its start with KINSOL's line "
                'search, and if that fails too, by pseudo-transient continuation (Newton steps '
                'on F + mu D du = 0 with mu falling as the residual does, at most 4 * '
                '`max_iterations` steps), which follows a ring sliding far along a stiff yarn '
                'where a line search crawls. `.false.`: full Newton steps only.'),
        Var('slack_stiffness', 'real', 1e-06, unit='1', range='>= 0',
            doc='Regularisation of the Newton solve, never of the answer. The residual is always '
                'that of the exact tension-only law (a slack string carries exactly zero). A '
                'slack string (stretch <= 1) adds to the Newton tangent the stiffness of a weak '
                'spring of rest length L0/2, `slack_stiffness * k_ref` (`k_ref` the law\'s '
                'stiffness at stretch 1), so the linear systems stay regular. A solve that fails '
                'with the exact law is predicted with that spring in the model, its weight '
                'falling from 0.1 to `slack_stiffness` by factors of 10, and then corrected with '
                'the exact law from there. 0 switches both off (a net at zero tension then has a '
                'singular tangent).'),
        Var('initial_step', 'real', 0.1, unit='knot interval', range='> 0',
            presets={'balanced': 0.05, 'accurate': 0.01},
            doc='First continuation step, as a fraction of the knot interval; at least '
                'min_step, capped at max_step.'),
        Var('min_step', 'real', 1e-06, unit='knot interval', range='> 0',
            doc='Smallest step, as a fraction of the knot interval being followed; min_step <= '
                'max_step, and min_step times every knot interval at least `100 * epsilon` '
                'times the largest absolute `&path time` (a shorter step would not advance the '
                'pseudo-time). A friction step whose stick/slip rounds fail at every step size '
                'down to min_step jumps (see *Slip instabilities*); any other step that fails '
                'there stops the run.'),
        Var('max_step', 'real', 0.25, unit='knot interval', range='> 0',
            presets={'balanced': 0.05, 'accurate': 0.01},
            doc='Largest step, as a fraction of the knot interval being followed: a path of N '
                'knot intervals takes at least N / max_step steps, whatever the spacing of its '
                'knots.'),
        Var('step_growth', 'real', 1.5, unit='1', range='>= 1',
            doc='Step growth factor after an easy step.'),
        Var('step_cut', 'real', 0.5, unit='1', range='(0, 1)',
            doc='Step cut factor after a failed step.'),
        Var('easy_iterations', 'integer', 4, range='>= 0',
            doc='A step that converges in at most this many Newton iterations is "easy" '
                '(under force control: those of the trial that holds the force).'),
        Var('max_step_cuts', 'integer', 30, range='>= 0',
            doc='Give up after this many consecutive step cuts.'),
        Var('scheme', 'character', 'monolithic', length=16, lower=True,
            choices=['monolithic', 'staggered'],
            presets={'balanced': 'monolithic', 'accurate': 'monolithic'},
            doc="Friction: `'monolithic'` solves positions and sliding together with a "
                "stick/slip active set; `'staggered'` is the paper's two-step scheme (elastic "
                'solve, then sliding); a step that its first round does not solve is finished '
                "by monolithic solves from that round's state (the alternation alone converges "
                'slowly), and where the rounds run out by one with every Newton fallback. '
                'Case-insensitive.'),
        Var('max_friction_iterations', 'integer', 200, range='>= 1',
            doc='Friction: most stick/slip active-set updates (monolithic) or elastic/sliding '
                'alternations (staggered) per load step. Along contacts at held nodes (pins, '
                'supports) a slip front moves along its yarn in one monolithic round (the '
                'capstan relation); across free crossings (knits, weaves) by about one passage '
                'per round, so a large clamped sample may need many rounds where its slip zone '
                'opens.'),
        Var('min_length_ratio', 'real', 0.05, unit='1', range='(0, 1)',
            doc="Friction: sliding never makes an element's reference length (and so its "
                "segment's) shorter than this fraction of its initial length. The passage then "
                'locks in that direction. Much shorter elements make the wrap angle at their '
                'nodes ill-conditioned (measured: elements at 1 % of their length stalled Newton '
                'on the woven benchmark net).'),
        Var('friction_tolerance', 'real', 1e-09, unit='1', range='> 0',
            doc='Friction: relative slack in the stick test T_max <= T_crit (1 + '
                'friction_tolerance) + band. The band is 10 times the uncertainty of the '
                "passage's own tensions at convergence: residual_tolerance times the larger of "
                'its two tensions (at least 1e-6 times the largest force of the scene), plus '
                'their rounding. No absolute number and no material stiffness: a frictionless '
                'passage slips as soon as its tensions differ by more than that.'),
    ]),
    Group('material', 'repeatable',
          'One yarn type and its force law (one group per yarn type).', [
        Var('name', 'character', '', length='name_length',
            doc=f'{NAME_RULE} `&yarn` and the geometry file refer to it (case-sensitive).'),
        Var('law', 'character', '', length=16, lower=True,
            choices=['linear', 'neo_hookean', 'table'], selects=True,
            doc='Required (case-insensitive).'),
        law_parameter('stiffness', 'N', '> 0', ['linear'], '`linear`: EA.'),
        law_parameter('modulus', 'Pa', '> 0', ['neo_hookean'], '`neo_hookean`: modulus C.'),
        law_parameter('area', 'm^2', '> 0', ['neo_hookean'],
                      '`neo_hookean`: undeformed cross-section S(1).'),
        Var('table_file', 'character', '', length='path_length', adjust=False, laws=['table'],
            doc='`table`: CSV file of (strain, force). The material code reads it. A '
                'relative name is taken from the working directory of the run, also from '
                "Python (README, *Relative paths*), not from the input file's folder. Its "
                'units: the header '
                '(`Elongation (%),Force (cN)`), `strain_unit` and `force_unit`, else 1 and N; '
                'see *Table files* below.'),
        Var('strain_unit', 'character', '', length=16, checked_by='table',
            default_doc="`''` (the header's, else `'1'`)",
            type_doc="character(16): `'1'`, `'-'`, `'%'`, `'permille'`, or a length: `'m'`, "
                     "`'cm'`, `'mm'`, `'um'`",
            doc='`table`: the unit of the strain column, as its header would state it; must '
                'agree with a unit the header states. A length makes the column an '
                'elongation, divided by `gauge_length`. Case-sensitive (`permille` in any '
                'case).'),
        Var('force_unit', 'character', '', length=16, checked_by='table',
            default_doc="`''` (the header's, else `'N'`)",
            type_doc="character(16): `'N'`, `'cN'`, `'mN'`, `'kN'`, `'gf'`, `'kgf'`, `'lbf'`",
            doc='`table`: the unit of the force column, as its header would state it; must '
                'agree with a unit the header states. Case-sensitive (`gf`, `kgf`, `lbf` in '
                'any case).'),
        Var('gauge_length', 'real', None, unit='m', range='> 0', checked_by='table',
            default_doc='not set',
            doc='`table`: initial length of the tensile specimen; required when the strain '
                'column is an elongation (a length unit), an error otherwise: strain = '
                'elongation / gauge_length. At most 5 m (500 mm is 0.5).'),
        Var('prestress', 'real', 0.0, unit='N', range='>= 0',
            doc='Pre-stress: every element of this yarn type starts with reference length L0 = l '
                '/ lambda_p, where f(lambda_p) = prestress and l is its length in the initial '
                "geometry, so it carries that tension there (the paper's knitting yarns carry 2 "
                'cN: `prestress = 0.02`). The initial geometry is then not in equilibrium in '
                'general; step 0 of the run finds the equilibrium. An error if the law does '
                'not reach that force at a stretch up to 2**60 (about 1.2e18; the same bound '
                'holds for `&yarn length0` and `stretch`).'),
    ]),
    Group('contact', 'repeatable',
          'The friction law where yarns of two types cross (one group per unordered pair).', [
        Var('materials', 'character', '', length='name_length', shape=2,
            doc='The two yarn types, names of `&material` groups (`materials = '
                "'cotton', 'wool'`): required unless `at` is set (then one yarn type or none)."),
        Var('law', 'character', '', length=32, lower=True,
            choices=['bonded', 'coulomb', 'adhesion', 'decaying_adhesion', 'general'],
            selects=True,
            doc='Required (case-insensitive).'),
        law_parameter('friction_coefficient', '1', '>= 0',
                      ['coulomb', 'adhesion', 'decaying_adhesion'],
                      'Friction coefficient mu. Every law but `bonded` and `general`.'),
        law_parameter('adhesion', 'N', '>= 0', ['adhesion', 'decaying_adhesion'],
                      'Adhesion beta (per radian of wrap angle). `adhesion` and '
                      '`decaying_adhesion`.'),
        law_parameter('decay_start', 'N', '>= 0', ['decaying_adhesion'],
                      'Tension w_d where the adhesion starts to decay. `decaying_adhesion`.'),
        law_parameter('decay_end', 'N', '>= 0', ['decaying_adhesion'],
                      'Tension s_d where the adhesion has vanished. `decaying_adhesion`.',
                      type_doc='real > `decay_start`'),
        Var('rate_table', 'character', '', length='path_length', adjust=False, laws=['general'],
            default_doc="`''` (none)",
            doc='`general`: CSV file of (T in N, g in N/rad), the rate of the general law T\' = '
                'g(T) (paper eqs. 37-39), read like a `&material table_file` (same CSV rules; '
                'a relative name is taken from the working directory of the run). The first row '
                'is T = 0 with g >= 0, T strictly increasing, g > 0 for T > 0, all finite; g is '
                'linear between rows and continues with the last slope beyond the last row, '
                'which therefore may not fall. See *The general friction law* below.'),
        Var('at', 'character', '', length='name_length', default_doc="`''` (a pair of types)",
            doc='The law of an `&obstacle` or `&ring` instead of a pair of yarn types: the name '
                'of that group. `materials(1)` then names the yarn type it applies to, or is '
                'left empty for every yarn type; `materials(2)` stays empty. See *Obstacles and '
                'rings* below.'),
    ]),
    Group('fabric', 'singleton',
          'A generated fabric (knitted with inlay, or woven) instead of &nodes, &yarn and '
          '&support groups.', fabric_vars(
        Var('kind', 'character', '', length=16, lower=True,
            choices=['knit', 'plain', 'twill', 'texgen'], default_doc='required',
            doc="`'knit'` (weft-knitted single jersey, optional inlay), `'plain'` (plain weave), "
                "`'twill'` (2/2 twill) or `'texgen'` (a periodic cell, or a clamped sample of "
                "copies of it, from a TexGen model file, "
                '`texgen_file`).'),
        Var('cells', 'integer', [4, 4], shape=2, range='>= 1',
            doc='Repeats along x and y: wales x courses (knit); weft yarns (crossings along x) x '
                'warp yarns (woven). A periodic plain weave needs even counts, a periodic twill '
                'multiples of 4. TexGen: copies of the cell in a clamped sample (not used for '
                'a periodic cell).'),
        Var('spacing', 'real', [-1.0, -1.0], shape=2, unit='m', range='> 0',
            default_doc='required',
            doc='Repeat spacing along x and y: wale and course spacing (knit); weft and warp '
                'yarn spacing (woven).'),
        Var('boundary', 'character', 'periodic', length=16, lower=True,
            choices=['periodic', 'clamped'],
            doc="`'periodic'`: a unit cell whose edge nodes are tied to the opposite edge (paper "
                'eq. 53), stretched by the macroscopic strain below; one node (`anchor`) is held '
                "against rigid translation. `'clamped'`: a finite sample, yarn ends at x = 0 "
                'held (`left`), those at the right edge pulled (`right`); for `texgen`, '
                '`cells` copies of the cell.'),
        Var('strain', 'real', 1.0, unit='1', range='[-0.9, 100]',
            doc='Engineering strain along x at p_disp = 1 (`1.0` stretches to twice the length). '
                "Periodic: of the cell's x period; clamped: of the sample's length."),
        Var('lateral_strain', 'real', 0.0, unit='1', range='[-0.9, 100]',
            doc='Periodic: engineering strain of the y period at p_disp = 1, prescribed. Give '
                'the measured lateral contraction if you know it; 0 holds the height. The height '
                'cannot be left free: a string network has no resistance to lateral compaction, '
                'because nothing models yarns jamming against each other. We tried making the y '
                'period one more unknown, with zero net y force across the cell. The '
                'pre-stressed plain-weave cell then collapsed to a lateral strain of -0.99999 at '
                "step 0, and the knit cell's initial state did not converge. For free lateral "
                "contraction, use a clamped sample with `sides = 'free'`, or hold a lateral force "
                '(`lateral_control`).'),
        Var('lateral_control', 'character', 'strain', length=16, lower=True,
            choices=['strain', 'force', 'ratio'],
            doc="Periodic: what holds the y period. `'strain'`: `lateral_strain` (prescribed). "
                "`'force'`: the membrane force n22 (N/m) is held at `lateral_force` at every step, "
                "the strain e22 an unknown. `'ratio'`: n22 = `force_ratio` * n11 at every step. "
                'A force-controlled y period is found by an outer iteration on e22 around each '
                'step (to 100 * residual_tolerance of the forces); where no e22 gives the '
                'force (the cell collapses laterally, see `lateral_strain`), the run stops '
                'with that message. `lateral_strain` must then be 0.'),
        Var('lateral_force', 'real', 0.0, unit='N/m', range='>= 0',
            doc="Periodic, `lateral_control = 'force'`: the membrane force n22 held (force "
                'across an x-parallel cell edge per unit current edge length, as in curve.csv).'),
        Var('force_ratio', 'real', 1.0, unit='1', range='[0, 100]',
            doc="Periodic, `lateral_control = 'ratio'`: n22 / n11 held at every step."),
        Var('axial_control', 'character', 'strain', length=16, lower=True,
            choices=['strain', 'force'],
            doc="Periodic: what holds the x period. `'strain'`: p_disp * `strain` (prescribed). "
                "`'force'`: the membrane force n11 (N/m) is held at p_disp * `axial_force` at "
                'every step, the strain e11 an unknown found like e22 under `lateral_control` '
                '(with both, around it); p_disp must stay > 0 (n11 = 0 lets the cell collapse '
                'along x: the run stops with that message). `strain` must then be left out.'),
        Var('axial_force', 'real', 0.0, unit='N/m', range='> 0',
            default_doc="required (`'force'`)",
            doc="Periodic, `axial_control = 'force'`: the membrane force n11 held at p_disp = 1 "
                '(force across a y-parallel cell edge per unit current edge length, as in '
                'curve.csv).'),
        Var('shear', 'real', 0.0, unit='1', range='[-10, 10]',
            doc='Periodic: simple shear of the cell at p_disp = 1, prescribed: the y period '
                'a2 = L20 (p_disp * shear e_x + (1 + e22) e_y), so an image one y period up '
                'moves by p_disp * shear * L20 along x; curve.csv reports gamma12 = '
                'atan(p_disp * shear / (1 + e22)) (rad). See *Shear* below.'),
        Var('sides', 'character', 'free', length=16, lower=True, choices=['free', 'rollers'],
            doc="Clamped: `'free'` side edges or `'rollers'`. Woven: rollers hold the weft ends "
                'in y and z (a selvedge); free weft ends of pre-stressed weft yarns cannot carry '
                'their tension, so woven strips need rollers. Knit: rollers hold the contacts of '
                'the first and last course in y. With free sides a cast-on and a bind-off '
                'thread close the first and the last course (`edge_material`; see *Clamped '
                'knit edges* below).'),
        Var('elements_per_segment', 'integer', 1, range='>= 1',
            doc='Elements per yarn segment between generated nodes. A string under tension is '
                'straight between contacts, so 1 is exact: `verification/fabrics` finds 2, 4 and '
                '8 give the same curve to 2e-14. More only cost time, most with sliding, where a '
                "passage's flow reaches every element of its two segments, which fills the "
                'sparse factors. Measured on `benchmarks/bench_friction` (woven net, 578 '
                'passages): 132 ms per load step with 4 elements per segment against 29 ms with '
                '1.'),
        fabric_material('knit_material', 'required (knit)', 'Yarn type of the loops.'),
        Var('head_width', 'real', 0.5, unit='1', range='[0.05, 0.95]',
            doc="Knit: width of a loop's head, as a fraction of the wale spacing. The loops are "
                'polygons through their contacts (a string under tension is straight between '
                'contacts): a loop is 2*spacing(2) + spacing(1) long.'),
        fabric_material('inlay_material', "`''` (no inlay)", 'Knit: yarn type of the inlay.'),
        Var('inlay_every', 'integer', 1, range='>= 1',
            doc='Knit: an inlay in every inlay_every-th course (0, k, 2k, ...).'),
        Var('inlay_offset', 'real', 0.5, unit='1', range='[0.05, 0.95]',
            doc='Knit: height of the inlay above its course line, as a fraction of the course '
                'spacing.'),
        *[fabric_material(name, 'required (woven)', 'Woven: yarn types along x (warp, the '
                          'loaded direction) and along y (weft).')
          for name in ('warp_material', 'weft_material')],
        Var('gap', 'real', None, unit='m',
            default_doc='required (woven, knit with inlay)',
            type_doc='real, 0 < gap < min(spacing)',
            doc='Gap-holder length: distance between the axes of the two yarns at a crossing.'),
        *[Var(name, 'real', None, shape='list', unit='1', default_doc='empty (factor 1)',
              doc=GAP_FACTOR) for name in ('gap_factor_p_disp', 'gap_factor')],
        Var('texgen_file', 'character', '', length='path_length', adjust=False,
            default_doc='required (texgen)',
            doc="TexGen: the model file (`.tg3`, TexGen's XML), relative to the working "
                'directory of the run (as `table_file`). Read without TexGen: one textile, '
                'periodic yarns with repeats along x and y (the cell), master nodes, '
                'interpolation, section width and height, GeometryScale. See *TexGen import* '
                'below.'),
        Var('texgen_materials', 'character', '', length='name_length', shape=64,
            default_doc='required (texgen)',
            doc="TexGen: the `&material` of TexGen's yarn 0, 1, 2, ... (by index): one "
                'name for every yarn, or one per yarn of the file (another count is an '
                'error: the yarns after a short list took its last name).'),
        Var('texgen_contact_tolerance', 'real', 0.05, unit='1', range='[0, 1]',
            doc='TexGen: two yarns are in contact where their centre lines come within (1 + '
                'this) times the sum of their half thicknesses (TexGen yarns that touch are '
                'exactly that far apart, up to its interpolation).'),
        Var('texgen_samples', 'integer', 16, range='[2, 1000]',
            doc='TexGen: points per master-node span of the sampled centre lines on which '
                'contacts are searched.'),
        Var('knit_depth', 'real', 0.0, unit='m',
            type_doc='real, 0 <= knit_depth < min(spacing)',
            doc="Knit: 0 makes the planar knit (a loop's head and the feet of the loop above "
                'share one node). A positive value makes it three-dimensional: the feet and '
                'sinkers lie at z = +knit_depth/2, the heads at -knit_depth/2, the legs slope '
                'between them, and each loop contact has a node on either yarn joined by a '
                'gap-holder of this length (the distance between the yarn axes: the yarn '
                'thickness). See *Three-dimensional knit* below.'),
        fabric_material('edge_material', '`knit_material`',
            doc="Knit, clamped with `sides = 'free'`: yarn type of the cast-on and bind-off "
                'threads that close the first and the last course (see *Clamped knit edges* '
                'below).'),
    )),
    Group('nodes', 'singleton',
          'Node coordinates (node ids 1..n in list order).', [
        Var('xyz', 'real', None, shape='list', max='max_coordinates', unit='m',
            doc='Node coordinates as a flat list `x1, y1, z1, x2, y2, z2, ...`. The count must '
                'be a multiple of 3. Node ids are 1..n in list order.'),
    ]),
    Group('geometry', 'singleton',
          'Node positions and yarns from a plain text file instead of &nodes and &yarn groups.', [
        Var('file', 'character', '', length='path_length', adjust=False, default_doc="`''` (none)",
            doc='Geometry file with the nodes and yarns (format below).'),
        Var('unit', 'character', '', length=16, checked_by='geometry',
            default_doc="`''` (the file's, else `'m'`)",
            type_doc="character(16): `'m'`, `'cm'`, `'mm'`, `'um'`",
            doc="The length unit of the file's coordinates and `length0` values, converted to "
                "m (the scene's unit); must agree with the file's `unit` line if it has one. "
                'Case-sensitive. Requires `file`.'),
    ]),
    Group('yarn', 'repeatable',
          'One yarn, a polyline through node ids, split into elements.', [
        Var('material', 'character', '', length='name_length',
            doc='Required: the name of a `&material`.'),
        Var('nodes', 'integer', None, shape='list',
            doc='Node ids along the yarn: at least 2, each in 1..n_nodes. Two consecutive ids '
                'may not be equal or at the same position. An id may come back later (loops), '
                'but no two segments of the net (of this yarn or another) may join the same two '
                'nodes.'),
        Var('elements_per_segment', 'integer', 1, range='>= 1',
            doc='Each segment between listed nodes is split into this many elements through new, '
                'evenly spaced nodes. Sliding at a contact node moves reference length into or '
                'out of the whole segment: each of its elements takes its share of the change, '
                'in proportion to its initial length. The new nodes are material points that a '
                'yarn does not slide through.'),
        Var('length0', 'real', None, shape='list', unit='m', range='> 0',
            default_doc='none (from the geometry)',
            doc='Reference length L0 of every element of the yarn, in order along it (one '
                'value per element: (number of nodes - 1) * elements_per_segment), so that a '
                'measured or computed pretensioned state is given exactly. Each > 0, with '
                'l / L0 (l: the element\'s initial length) in [2**-60, 2**60], the bound of a '
                '`prestress`. Not with `stretch`, nor on a yarn whose material has a '
                '`prestress`.'),
        Var('stretch', 'real', None, shape='list', unit='1', range='> 0',
            default_doc='none (1)',
            doc='Initial stretch lambda of every element of the yarn instead: L0 = l / lambda, '
                'l the element\'s length in the initial geometry (the operation `prestress` '
                'does with one lambda per material). One value per element, each in [2**-60, '
                '2**60] (about 8.7e-19 to 1.2e18), the bound of a `prestress`. Not with '
                '`length0`, nor with a `prestress` of the material.'),
    ]),
    Group('support', 'repeatable',
          'A named set of nodes whose listed components are prescribed.', [
        Var('name', 'character', '', length='name_length',
            doc=f"{NAME_RULE} Names the support's reaction-force columns in the curve CSV."),
        node_set('.'),
        Var('fix', 'character', 'xyz', length=3, lower=True,
            doc='The prescribed components: one or more of `x`, `y`, `z`, each once '
                '(case-insensitive).'),
        Var('displacement', 'real', [0.0, 0.0, 0.0], shape=3, unit='m', range='finite',
            doc='Displacement D at load factor p_disp = 1, per component. Prescribed position = '
                'initial position + p_disp(t) * D. A nonzero component outside `fix` is an '
                'error.'),
        channel_var('support', 'displacement', 'p_disp'),
    ]),
    Group('load', 'repeatable',
          'A force P (N) at load factor p_force = 1 on each listed node.', [
        node_set('.'),
        Var('force', 'real', [0.0, 0.0, 0.0], shape=3, unit='N', range='finite',
            doc='Force P on each listed node at load factor p_force = 1. Applied force = '
                'p_force(t) * P. A nonzero component on a coordinate that a support prescribes '
                'is an error.'),
        channel_var('load', 'force', 'p_force'),
    ]),
    Group('path', 'singleton',
          'The load path as knots over pseudo-time, linear in between.', [
        knot_list('time', 'pseudo-time', None, 'At least 2 knots, strictly increasing.'),
        knot_list('p_force', '1', 'zeros',
                  'Force factor at each knot (scales every `&load` force).'),
        knot_list('p_disp', '1', 'zeros',
                  'Displacement factor at each knot (scales every `&support` displacement).'),
        Var('channels', 'character', '', length='name_length', shape=8,
            default_doc="none (`'p_force'`, `'p_disp'`)", type_doc='character(64) x 8',
            doc='Names of independent load channels (at most 8), each one word of letters, '
                'digits, `_`, `-`, `.`, unique, and none of the other columns of `curve.csv`. '
                'Each `&load` and `&support` names the channel that scales it. Given, the '
                'factors come from `factors` and `p_force`, `p_disp` may not be set. Not with '
                '`&fabric`.'),
        knot_list('factors', '1', 'none',
                  'With `channels`: the factor of every channel at every knot, one row per '
                  'knot (the values of the channels in the order of `channels`), so n_knots * '
                  'n_channels values.'),
    ]),
    Group('output', 'singleton',
          'Where and what to write.', [
        Var('folder', 'character', 'out', length='path_length', adjust=False,
            doc='Folder for the results (not empty).'),
        Var('vtk_every', 'integer', 1, range='>= 0',
            doc='Write a VTK state every this many converged steps. 0 writes none. When it is '
                'above 0, the last step is always written.'),
        Var('vtk_format', 'character', 'binary', length=8, lower=True,
            choices=['binary', 'ascii'],
            doc="Encoding of the VTK state files: `'binary'` (appended, base64-encoded, VTK "
                "XML 1.0) or `'ascii'` (inline text, 17 significant digits: the same values)."),
        Var('progress', 'logical', True,
            doc='Progress lines on stderr.'),
        Var('node_reactions', 'logical', False,
            doc='Also write `reactions.csv`: the reaction of every constrained node at every '
                'converged step, in long format (columns `step,support,node,rx,ry,rz`; one row '
                'per node of each `&support` set, in the order the set lists them; N, the force '
                'the support applies on the net; 0 for a component the set does not fix). The '
                'rows of a set add up to its columns of `curve.csv`. ' + LIKE_CURVE),
        Var('contact_state', 'logical', True,
            doc='Write `contacts.csv` when the scene has sliding passages (a yarn through a '
                'contact node with a friction law): per converged step and passage, in long '
                'format, `step,passage,node,yarn,flow,mode,tension_min,tension_max,'
                'critical_tension,wrap_angle`. flow (m) is the reference length moved through '
                'the node since the start, from the element before the node (along the yarn) '
                "to the one after it; mode is `stick`, `forward` or `backward` (sliding towards "
                'the element after / before the node) or `locked` (stuck because the element '
                'on its low-tension side is at its minimum length, see `&solver '
                'min_length_ratio`); tensions in N (clipped at 0), critical_tension = '
                'T_crit(tension_min, wrap_angle), wrap_angle in rad. ' + LIKE_CURVE),
        Var('residual_history', 'logical', False,
            doc='Also print, per step, the scaled residual of every Newton iterate, max '
                '\\|F_i\\| / (level_i + noise_i / residual_tolerance) (see `&solver '
                'residual_tolerance`; converged at <= residual_tolerance), to see the '
                'convergence rate.'),
    ]),
    sliding_node_group(
        'obstacle', 'Fixed obstacles (pins, guides, capstan pegs): nodes at a prescribed '
        'position that yarns slide through.',
        "; it also names the reaction-force columns of the coordinates it holds (as a "
        "`&support`'s).",
        'Every coordinate of these nodes that no `&support` prescribes is held at its initial '
        'position; a `&support` that lists the node moves it (a moving pin).'),
    sliding_node_group(
        'ring', 'Free rings: nodes of free position that yarns slide through.', '.',
        'The position is free; a `&load` on the node is the force applied to the ring.'),
]
