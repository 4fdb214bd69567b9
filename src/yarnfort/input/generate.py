#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Make the namelist input layer from its one description (variables.py).

    generate.py fortran OUT.f90     the module yarnfort_input_groups (meson runs this)
    generate.py reference           the variable tables of inputs/REFERENCE.md, on stdout
    generate.py check REFERENCE.md  exit 1 (with a diff) if the tables there differ
    generate.py update REFERENCE.md rewrite the tables there
    generate.py python OUT.json     the description as JSON for the Python scene classes
                                    (installed in the package; meson runs this)

The module holds, per group: its config type (defaults, one doc line per variable), a
reader of one occurrence (each variable taken from the tokenizer's assignments by the
typed helpers of fields.f90: entries, lengths, case), the generic checks (range,
choices, the parameters of the selected law), the echo, and for all groups the names
and the --help summary.
"""
from __future__ import annotations

import dataclasses
import difflib
import json
import re
import sys
import textwrap
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from descriptors import LENGTHS, Group, Var  # noqa: E402
from variables import GROUPS  # noqa: E402

INDENT = "    "
WIDTH = 96


# ---------------------------------------------------------------- Fortran text helpers
def fortran_real(value: float) -> str:
    mantissa, _, exponent = repr(float(value)).partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    return mantissa + (f"e{int(exponent)}" if exponent else "") + "_wp"


def fortran_value(var: Var, value: object) -> str:
    if var.type == "character":
        return "'" + str(value).replace("'", "''") + "'"
    if var.type == "logical":
        return ".true." if value else ".false."
    if var.type == "real":
        return fortran_real(value)  # type: ignore[arg-type]
    return str(value)


def fortran_default(var: Var) -> str:
    values = [fortran_value(var, v) for v in (var.default if isinstance(var.default, list)
                                               else [var.default])]
    return values[0] if len(set(values)) == 1 else "[" + ", ".join(values) + "]"


def declaration(var: Var) -> str:
    kind = {"real": "real(wp)", "integer": "integer", "logical": "logical",
            "character": f"character(len={var.length})"}[var.type]
    if var.is_list:
        return f"{kind}, allocatable :: {var.name}(:)"
    if var.optional:
        return f"{kind}, allocatable :: {var.name}"
    shape = f"({var.size})" if var.size else ""
    return f"{kind} :: {var.name}{shape}"


def wrap_statement(text: str, indent: str) -> list[str]:
    """A Fortran statement split at blanks outside character constants, with '&'
    continuation lines."""
    if len(indent + text) <= WIDTH:
        return [indent + text]
    breaks = [m.start() for m in re.finditer(r"'[^']*'|\"[^\"]*\"| ", text) if m[0] == " "]
    lines, start, first = [], 0, True
    while len(text) - start > WIDTH - len(indent) - (0 if first else 4):
        room = WIDTH - len(indent) - (0 if first else 4) - 2
        fits = [i for i in breaks if start < i <= start + room]
        if not fits:
            break
        lines.append(text[start:fits[-1]])
        start, first = fits[-1] + 1, False
    lines.append(text[start:])
    return [indent + (INDENT if i else "") + line + (" &" if i < len(lines) - 1 else "")
            for i, line in enumerate(lines)]


def doc_comment(text: str, indent: str) -> list[str]:
    first = re.split(r"(?<=[.:;])\s", text.replace("`", ""), maxsplit=1)[0]
    return [indent + "!> " + line for line in textwrap.wrap(first, WIDTH - len(indent) - 4)]


def string_array(name: str, values: list[str]) -> str:
    length = max(len(v) for v in values)
    items = ", ".join(f"'{v}'" for v in values)
    return f"character(len=*), parameter :: {name}(*) = [character(len={length}) :: {items}]"


# ---------------------------------------------------------------- the Fortran module
def fill(template: str, at: str = INDENT, **parts: object) -> list[str]:
    """The lines of a template (dedented, then indented by `at`; '{name}' replaced by
    parts[name]) and a blank line; a line that is a lone '{name}' of a list part becomes its
    statements, wrapped, at its indent (an item (depth, text) one indent deeper per depth)."""
    out = []
    for line in textwrap.dedent(template).strip("\n").split("\n"):
        key, indent = line.strip()[1:-1], at + line[:len(line) - len(line.lstrip())]
        if isinstance(parts.get(key), list):
            for item in parts[key]:  # type: ignore[attr-defined]
                depth, text = item if isinstance(item, tuple) else (0, item)
                out += wrap_statement(text, indent + INDENT * depth)
        else:
            out += wrap_statement(line.strip().format(**parts), indent) if line else [""]
    return out + [""]


def range_check(var: Var, value: str, variable: str) -> list[str]:
    """The call checking `value` against var.range: the condition and the rule of its
    message (reals must also be finite)."""
    if var.range is None:
        return []
    text = var.range.strip()
    bound = fortran_real if var.type == "real" else str
    inside, rule = ".true.", ""
    one = re.fullmatch(r"(>=|>)\s*(\S+)", text)
    interval = re.fullmatch(r"([(\[])\s*(\S+),\s*(\S+)\s*([)\]])", text)
    if one:
        inside, rule = f"{value} {one[1]} {bound(one[2])}", f"must be {one[1]} {one[2]}"
        if rule == "must be > 0":
            rule = "must be positive"
    elif interval:
        lower, upper = ">" if interval[1] == "(" else ">=", "<" if interval[4] == ")" else "<="
        inside = (f"{value} {lower} {bound(interval[2])} .and. "
                  f"{value} {upper} {bound(interval[3])}")
        rule = f"must lie in {interval[1]}{interval[2]}, {interval[3]}{interval[4]}"
        if interval[1] + interval[4] == "()":
            rule = f"must lie strictly between {interval[2]} and {interval[3]}"
    elif text != "finite":
        raise ValueError(f"{var.name}: range {text!r} is not understood")
    return [f"call check_range(error, label, {variable}, {value}, {inside}, '{rule}')"]


def element_checks(var: Var) -> list[tuple[int, str]]:
    """The range checks of every entry of `var` (scalar, fixed array or list; an
    unallocated list has none)."""
    field = f"value%{var.name}"
    if not (var.size or var.is_list):
        return [(0, call) for call in range_check(var, field, f"'{var.name}'")]
    calls = range_check(var, f"{field}(i)", f"'{var.name}(' // format_integer(i) // ')'")
    if not calls:
        return []
    loop = [(0, f"do i = 1, {var.size or f'size({field})'}"), *[(1, c) for c in calls],
            (0, "end do")]
    if var.size:
        return loop
    return [(0, f"if (allocated({field})) then"), *[(d + 1, c) for d, c in loop], (0, "end if")]


def choices_name(group: Group, var: Var) -> str:
    return f"{group.name}_{var.name}_choices"


def law_block(var: Var, law_bound: list[Var]) -> list[tuple[int, str]]:
    """select case over the selected law: its parameters required, the others not set."""
    body = [(0, f"select case (trim(value%{var.name}))")]
    for law in var.choices or []:
        body.append((0, f"case ('{law}')"))
        for v in law_bound:
            needed = law in (v.laws or [])
            if v.type == "character":
                is_set, text = f"len_trim(value%{v.name}) > 0", f"quote_string(value%{v.name})"
            else:
                is_set, text = f"allocated(value%{v.name})", f"optional_text(value%{v.name})"
            body.append((1, f"call check_law_parameter(error, label, '{v.name}', {is_set}, "
                            f"{text}, '{law}', {'.true.' if needed else '.false.'})"))
            for call in range_check(v, f"value%{v.name}", f"'{v.name}'") if needed else []:
                body.append((1, call))
    return body + [(0, "end select")]


def check_routine(group: Group) -> list[str]:
    """check_<group>_variables: ranges, choices and law parameters, each check followed
    by a return on error."""
    checked = [v for v in group.variables if not v.checked_by]
    law_bound = [v for v in checked if v.laws]
    body: list[tuple[int, str]] = []
    for var in checked:
        if var.laws:
            continue
        for value, advice in (var.retired or {}).items():
            pieces = " // ".join(f'"{piece} "' for piece in textwrap.wrap(advice, 50))
            body.append((0, f"call check_retired(error, label, '{var.name}', "
                            f"value%{var.name}, '{value}', {pieces})"))
        if var.choices:
            required = ".true." if var.selects else ".false."
            body.append((0, f"call check_choice(error, label, '{var.name}', value%{var.name}, "
                            f"{choices_name(group, var)}, {required})"))
        if var.selects and law_bound:
            body += law_block(var, law_bound)
        elif var.type in ("real", "integer"):
            body += element_checks(var)
    if not body:
        return []
    steps = []
    for depth, line in body:
        steps.append((depth, line))
        if line.startswith("call check_"):
            steps.append((depth, "if (allocated(error)) return"))
    while steps[-1][1] == "if (allocated(error)) return":
        steps.pop()
    return fill("""
        !> The checks of &{name} that its description gives: ranges, choices and
        !> the parameters of the selected law. `label` names the group in messages.
        subroutine check_{name}_variables(value, label, error)
            type({type}), intent(in) :: value
            character(len=*), intent(in) :: label
            type(error_type), allocatable, intent(out) :: error
            {loops}

            {steps}
        end subroutine check_{name}_variables
        """, name=group.name, type=group.type_name, steps=steps,
        loops=["integer :: i"] if any(line.startswith("do i") for _, line in body) else [])


def read_routine(group: Group) -> list[str]:
    """read_<group>: one occurrence from its assignments; read_<group>_groups: all."""
    takes = []
    for var in group.variables:
        args = (f"sets, label, '{var.name}', value%{var.name}, error, "
                f"{'.true.' if var.lower else '.false.'}, "
                f"{'.true.' if var.adjust and var.type == 'character' else '.false.'}")
        if var.optional:
            takes.append(f"call take_optional(sets, label, '{var.name}', value%{var.name}, "
                         "error)")
        elif var.is_list:
            takes += [f"call list_length(sets, label, '{var.name}', {var.max}, n, error)",
                      "if (allocated(error)) return", f"allocate(value%{var.name}(n))",
                      f"call take_array({args}, most={var.max})"]
        else:
            takes.append(f"call take_{'array' if var.size else 'scalar'}({args})")
        takes.append("if (allocated(error)) return")
    one = fill("""
        !> The `occurrence`-th &{name} group (0 for a singleton) into `value`.
        subroutine read_{name}(scan, occurrence, value, error)
            type(namelist_scan_type), intent(in) :: scan
            integer, intent(in) :: occurrence
            type({type}), intent(inout) :: value
            type(error_type), allocatable, intent(out) :: error
            type(assignment_type), allocatable :: sets(:)
            character(len=:), allocatable :: label
            integer :: n

            label = group_label('{name}', occurrence)
            call get_assignments(scan, '{name}', occurrence, {name}_variables, sets, error)
            if (allocated(error)) return
            {takes}
        end subroutine read_{name}

        """, name=group.name, type=group.type_name,
        takes=takes + [f"call apply_{group.name}_preset(sets, value)"] if preset_routine(group)
        else takes[:-1])
    if group.kind == "singleton":
        return one + fill("""
            !> The &{name} group into `value` if there is one (`value` is unchanged otherwise).
            subroutine read_{name}_groups(scan, value, error)
                type(namelist_scan_type), intent(in) :: scan
                type({type}), intent(inout) :: value
                type(error_type), allocatable, intent(out) :: error

                if (scan%count_group('{name}') > 0) call read_{name}(scan, 0, value, error)
            end subroutine read_{name}_groups
            """, name=group.name, type=group.type_name)
    return one + fill("""
        !> Every &{name} group, in the order of the text.
        subroutine read_{name}_groups(scan, values, error)
            type(namelist_scan_type), intent(in) :: scan
            type({type}), allocatable, intent(out) :: values(:)
            type(error_type), allocatable, intent(out) :: error
            integer :: k

            allocate(values(scan%count_group('{name}')))
            do k = 1, size(values)
                call read_{name}(scan, k, values(k), error)
                if (allocated(error)) return
            end do
        end subroutine read_{name}_groups
        """, name=group.name, type=group.type_name)


def preset_routine(group: Group) -> list[str]:
    preset = [v for v in group.variables if v.presets]
    if not preset:
        return []
    cases = []
    for name in next(v for v in group.variables if v.name == "preset").choices or []:
        settings = [(1, f"if (.not. is_assigned(sets, '{v.name}')) "
                        f"value%{v.name} = {fortran_value(v, v.presets[name])}")
                    for v in preset if name in v.presets]  # type: ignore[operator]
        cases += [f"case ('{name}')", *settings] if settings else []
    return fill("""
        !> The values the preset named by `value%preset` gives the variables of &{name}
        !> that the input does not set (none for another name).
        subroutine apply_{name}_preset(sets, value)
            type(assignment_type), intent(in) :: sets(:)
            type({type}), intent(inout) :: value

            select case (trim(value%preset))
            {cases}
            end select
        end subroutine apply_{name}_preset
        """, name=group.name, type=group.type_name, cases=cases)


def write_routine(group: Group) -> list[str]:
    puts = []
    for var in group.variables:
        field = f"value%{var.name}"
        if var.is_list:
            puts.append(f"if (allocated({field})) call put_list(unit, '{var.name}', {field})")
            continue
        if var.optional:
            puts.append(f"if (allocated({field})) call put(unit, indent // '{var.name} = ' "
                        f"// format_real({field}))")
            continue
        text = {"character": "quote_string({})", "real": "format_real({})",
                "integer": "format_integer({})",
                "logical": "trim(merge('.true. ', '.false.', {}))"}[var.type]
        entries = [f"{field}({k})" for k in range(1, var.size + 1)] if var.size else [field]
        joined = " // ', ' // ".join(text.format(entry) for entry in entries)
        puts.append(f"call put(unit, indent // '{var.name} = ' // {joined})")
    out = fill("""
        !> Write `value` as a &{name} group, every variable with its value.
        subroutine write_{name}(unit, value)
            integer, intent(in) :: unit
            type({type}), intent(in) :: value

            call put(unit, '&{name}')
            {puts}
            call put(unit, '/')
        end subroutine write_{name}
        """, name=group.name, type=group.type_name, puts=puts)
    if group.kind == "singleton":
        return out
    return out + fill("""
        !> Write each of `values` as a &{name} group.
        subroutine write_{name}_groups(unit, values)
            integer, intent(in) :: unit
            type({type}), allocatable, intent(in) :: values(:)
            integer :: k

            if (.not. allocated(values)) return
            do k = 1, size(values)
                call write_{name}(unit, values(k))
            end do
        end subroutine write_{name}_groups
        """, name=group.name, type=group.type_name)


def type_definition(group: Group) -> list[str]:
    out = doc_comment(f"&{group.name}: {group.doc}", INDENT)
    out.append(f"{INDENT}type, public :: {group.type_name}")
    for var in group.variables:
        default = "" if var.is_list or var.optional else f" = {fortran_default(var)}"
        out += doc_comment(var.doc, INDENT * 2) + [INDENT * 2 + declaration(var) + default]
    return out + [f"{INDENT}end type {group.type_name}", ""]


def help_lines() -> list[str]:
    lines = ["Namelist groups and their variables (every default, unit and range:",
             "inputs/REFERENCE.md):"]
    for group in GROUPS:
        head = f"  &{group.name} ({group.kind}): "
        lines += textwrap.wrap(head + " ".join(v.name for v in group.variables), 79,
                               subsequent_indent="      ")
    return lines


def fortran_module() -> str:
    publics, names = [], []
    for group in GROUPS:
        publics += [f"read_{group.name}_groups", f"write_{group.name}"]
        publics += [f"write_{group.name}_groups"] if group.kind == "repeatable" else []
        publics += [f"check_{group.name}_variables"] if check_routine(group) else []
        names.append(string_array(f"{group.name}_variables", [v.name for v in group.variables]))
        for var in (v for v in group.variables if v.choices):
            names += [f"!> Values of &{group.name} {var.name}."]
            names.append(string_array(choices_name(group, var), var.choices or []))
    choices = [choices_name(g, v) for g in GROUPS for v in g.variables if v.choices]
    out = fill("""
        ! SPDX-License-Identifier: MIT
        ! Generated by src/yarnfort/input/generate.py from variables.py: do not edit.
        !> The namelist groups as described in variables.py: config types, one reader, the
        !> generic checks and the echo per group, the group and variable names and the --help
        !> summary. The helpers they call are in yarnfort_input_fields.
        module yarnfort_input_groups
            use yarnfort_kinds, only: wp
            use yarnfort_error, only: error_type
            use yarnfort_text, only: format_integer, format_real, quote_string
            use yarnfort_input_scan, only: namelist_scan_type, assignment_type, get_assignments
            use yarnfort_input_fields, only: {fields}
            implicit none
            private

            public :: {publics}
            public :: group_names, singleton_names, help_lines, name_length, path_length
            public :: {choices}

            {lengths}
            !> All group names, in the order they are read and echoed.
            {group_names}
            !> Groups that may appear at most once.
            {singleton_names}
            {names}
            !> The group and variable summary of --help.
            {help}

        """, at="", publics=", ".join(publics), choices=", ".join(choices),
        fields="max_list, max_coordinates, group_label, take_scalar, take_array, list_length, "
        "is_assigned, check_range, check_choice, check_retired, check_law_parameter, put, "
        "put_list, indent, take_optional, optional_text",
        lengths=[f"integer, parameter :: {k} = {v}" for k, v in LENGTHS.items()],
        group_names=[string_array("group_names", [g.name for g in GROUPS])],
        singleton_names=[string_array("singleton_names",
                                      [g.name for g in GROUPS if g.kind == "singleton"])],
        names=names, help=[string_array("help_lines", help_lines())])
    for group in GROUPS:
        out += type_definition(group)
    out += ["contains", ""]
    for group in GROUPS:
        out += read_routine(group) + preset_routine(group) + write_routine(group)
        out += check_routine(group)
    return "\n".join(out + ["end module yarnfort_input_groups"]) + "\n"


# ---------------------------------------------------------------- REFERENCE.md tables
def default_text(var: Var) -> str:
    if var.default_doc is not None:
        return var.default_doc
    if var.is_list:
        return "none"
    values = var.default if isinstance(var.default, list) else [var.default]
    text = ", ".join(fortran_real(v)[:-3] if var.type == "real" else
                     fortran_value(var, v) for v in values)  # type: ignore[arg-type]
    return f"`{text}`"


def type_text(var: Var) -> str:
    if var.type_doc is not None:
        return var.type_doc
    text = var.type if var.type != "character" else f"character({var.char_length})"
    if var.is_list:
        text += " list"
    elif var.size:
        text += f" x {var.size}"
    if var.choices:
        text += ": " + ", ".join(f"`'{c}'`" for c in var.choices)
    elif var.range and var.range != "finite":
        text += (" in " if var.range[0] in "([" else " ") + var.range
    return text


def reference_table(group: Group) -> str:
    rows = ["| variable | type | default | unit | meaning |", "|---|---|---|---|---|"]
    for var in group.variables:
        unit = f" {var.unit} " if var.unit else " "
        rows.append(f"| `{var.name}` | {type_text(var)} | {default_text(var)} |{unit}"
                    f"| {var.doc} |")
    return "\n".join(rows)


#: A group's heading, the text up to its variable table (before the next heading), the table.
SECTION = re.compile(r"^(## `&(\w+)`(?:(?!^## )[\s\S])*?)^\| variable \| type \| default \| "
                     r"unit \| meaning \|\n(?:\|.*\n)+", re.MULTILINE)


def with_tables(text: str) -> str:
    """REFERENCE.md with each group's variable table (the first after its heading)
    replaced by the generated one."""
    groups = {g.name: g for g in GROUPS}
    found = [m[2] for m in SECTION.finditer(text)]
    if sorted(found) != sorted(groups):
        raise SystemExit(f"REFERENCE.md: no section or no variable table for "
                         f"{sorted(set(groups) - set(found))} or a section twice")
    return SECTION.sub(lambda m: m[1] + reference_table(groups[m[2]]) + "\n", text)


# ---------------------------------------------------------------- Python description
def python_description() -> str:
    """Every group and variable as JSON (the fields of descriptors.py, a character
    variable's length resolved), which yarnfort.scene builds its group classes from."""
    groups = []
    for group in GROUPS:
        variables = []
        for var in group.variables:
            entry = dataclasses.asdict(var)
            if var.type == "character":
                entry["length"] = var.char_length
            variables.append(entry)
        groups.append({"name": group.name, "kind": group.kind, "doc": group.doc,
                       "variables": variables})
    return json.dumps({"groups": groups}, indent=1) + "\n"


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "fortran":
        Path(argv[1]).write_text(fortran_module())
    elif len(argv) == 2 and argv[0] == "python":
        Path(argv[1]).write_text(python_description())
    elif argv == ["reference"]:
        print("\n\n".join(f"## `&{g.name}`\n\n{reference_table(g)}" for g in GROUPS))
    elif len(argv) == 2 and argv[0] in ("check", "update"):
        path = Path(argv[1])
        text = path.read_text()
        wanted = with_tables(text)
        if argv[0] == "update":
            path.write_text(wanted)
        elif wanted != text:
            sys.stdout.writelines(difflib.unified_diff(
                text.splitlines(True), wanted.splitlines(True), str(path),
                "from variables.py"))
            return 1
    else:
        print(__doc__, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
