#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Make the namelist input layer from its one description (variables.py).

    generate.py fortran OUT.f90     the module yarnfort_input_groups (meson runs this)
    generate.py reference           the variable tables of inputs/REFERENCE.md, on stdout
    generate.py check REFERENCE.md  exit 1 (with a diff) if the tables there differ
    generate.py update REFERENCE.md rewrite the tables there

The module holds, per group: its config type (defaults, one doc line per variable), a
reader of one occurrence (each variable taken from the tokenizer's assignments by the
typed helpers of fields.f90: entries, lengths, case), the generic checks (range,
choices, the parameters of the selected law), the echo, and for all groups the names
and the --help summary.
"""
from __future__ import annotations

import difflib
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
    text = repr(float(value))
    if "e" in text:
        mantissa, exponent = text.split("e")
        if "." not in mantissa:
            mantissa += ".0"
        text = f"{mantissa}e{int(exponent)}"
    elif "." not in text:
        text += ".0"
    return text + "_wp"


def fortran_value(var: Var, value: object) -> str:
    if var.type == "character":
        return "'" + str(value).replace("'", "''") + "'"
    if var.type == "logical":
        return ".true." if value else ".false."
    if var.type == "real":
        return fortran_real(value)  # type: ignore[arg-type]
    return str(value)


def fortran_default(var: Var) -> str:
    if isinstance(var.default, list):
        if len(set(map(str, var.default))) == 1:
            return fortran_value(var, var.default[0])
        return "[" + ", ".join(fortran_value(var, v) for v in var.default) + "]"
    return fortran_value(var, var.default)


def declaration(var: Var, buffer: bool = False) -> str:
    if var.type == "character":
        kind = "character(len=buffer_length)" if buffer else f"character(len={var.length})"
    else:
        kind = {"real": "real(wp)", "integer": "integer", "logical": "logical"}[var.type]
    if var.is_list:
        return f"{kind}, allocatable :: {var.name}(:)"
    shape = f"({var.size})" if var.size else ""
    return f"{kind} :: {var.name}{shape}"


def wrap_statement(text: str, indent: str) -> list[str]:
    """A Fortran statement split at blanks outside character constants, with '&'
    continuation lines."""
    if len(indent + text) <= WIDTH:
        return [indent + text]
    breaks, quote = [], ""
    for i, c in enumerate(text):
        if quote:
            quote = "" if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c == " ":
            breaks.append(i)
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


def string_array(name: str, values: list[str], indent: str) -> list[str]:
    length = max(len(v) for v in values)
    items = ", ".join(f"'{v}'" for v in values)
    return wrap_statement(f"character(len=*), parameter :: {name}(*) = "
                          f"[character(len={length}) :: {items}]", indent)


# ---------------------------------------------------------------- the Fortran module
def range_call(var: Var, label: str, value: str, variable: str) -> list[str]:
    """The call checking `value` against var.range (reals and integers)."""
    if var.range is None:
        return []
    text = var.range.strip()
    if var.type == "integer":
        minimum = re.fullmatch(r">=\s*(-?\d+)", text)
        if not minimum:
            raise ValueError(f"{var.name}: integer range {text!r} is not '>= n'")
        return [f"call check_at_least(error, {label}, {variable}, {value}, {minimum[1]})"]
    if text == "finite":
        return [f"call check_real(error, {label}, {variable}, {value})"]
    one = re.fullmatch(r"(>=|>)\s*(\S+)", text)
    if one:
        bound = one[2]
        return [f"call check_real(error, {label}, {variable}, {value}, "
                f"lower={fortran_real(float(bound))}, lower_text='{bound}', "
                f"lower_open={'.true.' if one[1] == '>' else '.false.'})"]
    interval = re.fullmatch(r"([(\[])\s*(\S+),\s*(\S+)\s*([)\]])", text)
    if interval:
        lo, hi = interval[2], interval[3]
        return [f"call check_real(error, {label}, {variable}, {value}, "
                f"lower={fortran_real(float(lo))}, lower_text='{lo}', "
                f"lower_open={'.true.' if interval[1] == '(' else '.false.'}, "
                f"upper={fortran_real(float(hi))}, upper_text='{hi}', "
                f"upper_open={'.true.' if interval[4] == ')' else '.false.'})"]
    raise ValueError(f"{var.name}: range {text!r} is not understood")


def element_checks(var: Var, calls_for) -> list[tuple[int, str]]:
    """Checks of every entry of `var` (scalar, fixed array or list), as (depth, line)."""
    field = f"value%{var.name}"
    if var.size or var.is_list:
        calls = calls_for(f"{field}(i)", f"'{var.name}(' // format_integer(i) // ')'")
        if not calls:
            return []
        upper = str(var.size) if var.size else f"size({field})"
        lines = [(0, f"do i = 1, {upper}")]
        for call in calls:
            lines += [(1, call), (1, "if (allocated(error)) return")]
        return lines + [(0, "end do")]
    lines = []
    for call in calls_for(field, f"'{var.name}'"):
        lines += [(0, call), (0, "if (allocated(error)) return")]
    return lines


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
                is_set = f".not. (value%{v.name} == {fortran_default(v)})"
                text = f"format_real(value%{v.name})"
            body.append((1, f"call check_law_parameter(error, label, '{v.name}', {is_set}, "
                            f"{text}, '{law}', {'.true.' if needed else '.false.'})"))
            for call in range_call(v, "label", f"value%{v.name}", f"'{v.name}'") if needed else []:
                body += [(1, "if (allocated(error)) return"), (1, call)]
            body.append((1, "if (allocated(error)) return"))
    return body + [(0, "end select")]


def check_routine(group: Group) -> list[str]:
    checked = [v for v in group.variables if not v.checked_by]
    law_bound = [v for v in checked if v.laws]
    body: list[tuple[int, str]] = []
    for var in checked:
        if var.laws:
            continue
        if var.choices:
            body += [(0, f"call check_choice(error, label, '{var.name}', value%{var.name}, "
                         f"{choices_name(group, var)}, {'.true.' if var.selects else '.false.'})"),
                     (0, "if (allocated(error)) return")]
        if var.selects and law_bound:
            body += law_block(var, law_bound)
        elif var.type in ("real", "integer"):
            body += element_checks(var, lambda value, name, v=var: range_call(
                v, "label", value, name))
    if not body:
        return []
    if body[-1][1] == "if (allocated(error)) return":
        body = body[:-1]
    out = [f"{INDENT}!> The checks of &{group.name} that its description gives: ranges, "
           "choices and",
           f"{INDENT}!> the parameters of the selected law. `label` names the group in "
           "messages.",
           f"{INDENT}subroutine check_{group.name}_variables(value, label, error)",
           f"{INDENT * 2}type({group.type_name}), intent(in) :: value",
           f"{INDENT * 2}character(len=*), intent(in) :: label",
           f"{INDENT * 2}type(error_type), allocatable, intent(out) :: error"]
    if any(line.startswith("do i") for _, line in body):
        out.append(f"{INDENT * 2}integer :: i")
    out.append("")
    for depth, line in body:
        out += wrap_statement(line, INDENT * (2 + depth))
    out.append(f"{INDENT}end subroutine check_{group.name}_variables")
    return out + [""]


def read_routine(group: Group) -> list[str]:
    """read_<group>: one occurrence from its assignments; read_<group>_groups: all."""
    i2, i3 = INDENT * 2, INDENT * 3
    name = group.name
    out = [f"{INDENT}!> The `occurrence`-th &{name} group (0 for a singleton) into `value`.",
           f"{INDENT}subroutine read_{name}(scan, occurrence, value, error)",
           f"{i2}type(namelist_scan_type), intent(in) :: scan",
           f"{i2}integer, intent(in) :: occurrence",
           f"{i2}type({group.type_name}), intent(inout) :: value",
           f"{i2}type(error_type), allocatable, intent(out) :: error",
           f"{i2}type(assignment_type), allocatable :: sets(:)",
           f"{i2}character(len=:), allocatable :: label",
           f"{i2}integer :: n", "",
           f"{i2}label = group_label('{name}', occurrence)",
           f"{i2}call get_assignments(scan, '{name}', occurrence, {name}_variables, sets, error)",
           f"{i2}if (allocated(error)) return"]
    for var in group.variables:
        args = (f"sets, label, '{var.name}', value%{var.name}, error, "
                f"{'.true.' if var.lower else '.false.'}, "
                f"{'.true.' if var.adjust and var.type == 'character' else '.false.'}")
        if var.is_list:
            out += wrap_statement(f"call list_length(sets, label, '{var.name}', {var.max}, n, "
                                  "error)", i2)
            out += [f"{i2}if (allocated(error)) return", f"{i2}allocate(value%{var.name}(n))"]
        kind = "array" if var.is_list or var.size else "scalar"
        if var.is_list:
            args += f", most={var.max}"
        out += wrap_statement(f"call take_{kind}({args})", i2)
        out.append(f"{i2}if (allocated(error)) return")
    out = out[:-1] + [f"{INDENT}end subroutine read_{name}", ""]
    if group.kind == "singleton":
        return out + [f"{INDENT}!> The &{name} group into `value` if there is one (`value` is "
                      "unchanged otherwise).",
                      f"{INDENT}subroutine read_{name}_groups(scan, value, error)",
                      f"{i2}type(namelist_scan_type), intent(in) :: scan",
                      f"{i2}type({group.type_name}), intent(inout) :: value",
                      f"{i2}type(error_type), allocatable, intent(out) :: error", "",
                      f"{i2}if (scan%count_group('{name}') > 0) call read_{name}(scan, 0, "
                      "value, error)",
                      f"{INDENT}end subroutine read_{name}_groups", ""]
    return out + [f"{INDENT}!> Every &{name} group, in the order of the text.",
                  f"{INDENT}subroutine read_{name}_groups(scan, values, error)",
                  f"{i2}type(namelist_scan_type), intent(in) :: scan",
                  f"{i2}type({group.type_name}), allocatable, intent(out) :: values(:)",
                  f"{i2}type(error_type), allocatable, intent(out) :: error",
                  f"{i2}integer :: k", "",
                  f"{i2}allocate(values(scan%count_group('{name}')))",
                  f"{i2}do k = 1, size(values)",
                  f"{i3}call read_{name}(scan, k, values(k), error)",
                  f"{i3}if (allocated(error)) return",
                  f"{i2}end do",
                  f"{INDENT}end subroutine read_{name}_groups", ""]


def preset_routine(group: Group) -> list[str]:
    preset = [v for v in group.variables if v.presets]
    if not preset:
        return []
    i2, i3 = INDENT * 2, INDENT * 3
    out = [f"{INDENT}!> The values the preset named by `value%preset` gives the variables of "
           f"&{group.name}",
           f"{INDENT}!> that the input does not set (none for another name).",
           f"{INDENT}subroutine apply_{group.name}_preset(scan, value)",
           f"{i2}type(namelist_scan_type), intent(in) :: scan",
           f"{i2}type({group.type_name}), intent(inout) :: value", "",
           f"{i2}select case (trim(value%preset))"]
    names = [c for c in next(v for v in group.variables if v.name == "preset").choices
             if any(c in v.presets for v in preset)]
    for name in names:
        out.append(f"{i2}case ('{name}')")
        for var in preset:
            if name in var.presets:
                out += wrap_statement(f"if (.not. scan%is_set('{group.name}', 1, '{var.name}')) "
                                      f"value%{var.name} = {fortran_value(var, var.presets[name])}",
                                      i3)
    return out + [f"{i2}end select", f"{INDENT}end subroutine apply_{group.name}_preset", ""]


def write_routine(group: Group) -> list[str]:
    i2 = INDENT * 2
    out = [f"{INDENT}!> Write `value` as a &{group.name} group, every variable with its value.",
           f"{INDENT}subroutine write_{group.name}(unit, value)",
           f"{i2}integer, intent(in) :: unit",
           f"{i2}type({group.type_name}), intent(in) :: value", "",
           f"{i2}call put(unit, '&{group.name}')"]
    for var in group.variables:
        field = f"value%{var.name}"
        if var.is_list:
            out += wrap_statement(f"if (allocated({field})) call put_list(unit, "
                                  f"'{var.name}', {field})", i2)
            continue
        text = {"character": "quote_string", "real": "format_real",
                "integer": "format_integer", "logical": "format_logical"}[var.type]
        if var.size:
            joined = f" // ', ' // ".join(f"{text}({field}({k}))" for k in range(1, var.size + 1))
        else:
            joined = f"{text}({field})"
        out += wrap_statement(f"call put(unit, indent // '{var.name} = ' // {joined})", i2)
    out += [f"{i2}call put(unit, '/')", f"{INDENT}end subroutine write_{group.name}", ""]
    if group.kind == "repeatable":
        out += [f"{INDENT}!> Write each of `values` as a &{group.name} group.",
                f"{INDENT}subroutine write_{group.name}_groups(unit, values)",
                f"{i2}integer, intent(in) :: unit",
                f"{i2}type({group.type_name}), allocatable, intent(in) :: values(:)",
                f"{i2}integer :: k", "",
                f"{i2}if (.not. allocated(values)) return",
                f"{i2}do k = 1, size(values)",
                f"{i2}{INDENT}call write_{group.name}(unit, values(k))",
                f"{i2}end do",
                f"{INDENT}end subroutine write_{group.name}_groups", ""]
    return out


def type_definition(group: Group) -> list[str]:
    out = doc_comment(f"&{group.name}: {group.doc}", INDENT)
    out.append(f"{INDENT}type, public :: {group.type_name}")
    for var in group.variables:
        out += doc_comment(var.doc, INDENT * 2)
        text = declaration(var)
        if not var.is_list:
            text += f" = {fortran_default(var)}"
        out.append(INDENT * 2 + text)
    out += [f"{INDENT}end type {group.type_name}", ""]
    return out


def help_lines() -> list[str]:
    lines = ["Namelist groups and their variables (every default, unit and range:",
             "inputs/REFERENCE.md):"]
    for group in GROUPS:
        head = f"  &{group.name} ({group.kind}): "
        lines += textwrap.wrap(head + " ".join(v.name for v in group.variables), 79,
                               subsequent_indent="      ")
    return lines


def fortran_module() -> str:
    out = ["! SPDX-License-Identifier: MIT",
           "! Generated by src/yarnfort/input/generate.py from variables.py: do not edit.",
           "!> The namelist groups as described in variables.py: config types, one reader, "
           "the",
           "!> generic checks and the echo per group, the group and variable names and the "
           "--help",
           "!> summary. The helpers they call are in yarnfort_input_fields.",
           "module yarnfort_input_groups",
           f"{INDENT}use yarnfort_kinds, only: wp",
           f"{INDENT}use yarnfort_error, only: error_type",
           f"{INDENT}use yarnfort_text, only: format_integer, format_real, quote_string",
           f"{INDENT}use yarnfort_input_scan, only: namelist_scan_type, assignment_type, "
           "get_assignments",
           f"{INDENT}use yarnfort_input_fields, only: max_list, max_coordinates, group_label, &",
           f"{INDENT * 3}take_scalar, take_array, list_length, check_real, check_at_least, &",
           f"{INDENT * 3}check_choice, check_law_parameter, put, put_list, format_logical, indent",
           f"{INDENT}implicit none",
           f"{INDENT}private", ""]
    publics = []
    for group in GROUPS:
        publics += [f"read_{group.name}_groups", f"write_{group.name}"]
        if group.kind == "repeatable":
            publics.append(f"write_{group.name}_groups")
        if check_routine(group):
            publics.append(f"check_{group.name}_variables")
        if preset_routine(group):
            publics.append(f"apply_{group.name}_preset")
    out += wrap_statement("public :: " + ", ".join(publics), INDENT)
    out += wrap_statement("public :: group_names, singleton_names, help_lines, "
                          "name_length, path_length", INDENT)
    choice_names = [choices_name(g, v) for g in GROUPS for v in g.variables if v.choices]
    out += wrap_statement("public :: " + ", ".join(choice_names), INDENT)
    out.append("")
    for name, value in LENGTHS.items():
        out.append(f"{INDENT}integer, parameter :: {name} = {value}")
    out.append(f"{INDENT}!> All group names, in the order they are read and echoed.")
    out += string_array("group_names", [g.name for g in GROUPS], INDENT)
    out.append(f"{INDENT}!> Groups that may appear at most once.")
    out += string_array("singleton_names", [g.name for g in GROUPS if g.kind == "singleton"],
                        INDENT)
    for group in GROUPS:
        out += string_array(f"{group.name}_variables", [v.name for v in group.variables],
                            INDENT)
        for var in group.variables:
            if var.choices:
                out.append(f"{INDENT}!> Values of &{group.name} {var.name}.")
                out += string_array(choices_name(group, var), var.choices, INDENT)
    out.append(f"{INDENT}!> The group and variable summary of --help.")
    out += string_array("help_lines", help_lines(), INDENT)
    out.append("")
    for group in GROUPS:
        out += type_definition(group)
    out += ["contains", ""]
    for group in GROUPS:
        out += read_routine(group)
        out += preset_routine(group)
        out += write_routine(group)
        out += check_routine(group)
    out.append("end module yarnfort_input_groups")
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------- REFERENCE.md tables
def markdown_real(value: float) -> str:
    return fortran_real(value)[:-3]


def default_text(var: Var) -> str:
    if var.default_doc is not None:
        return var.default_doc
    if var.is_list:
        return "none"
    values = var.default if isinstance(var.default, list) else [var.default]
    text = ", ".join(markdown_real(v) if var.type == "real" else
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


TABLE = re.compile(r"^\| variable \| type \| default \| unit \| meaning \|\n(?:\|.*\n)+",
                   re.MULTILINE)
HEADING = re.compile(r"^## `&(\w+)`", re.MULTILINE)


def with_tables(text: str) -> str:
    """REFERENCE.md with each group's variable table (the first after its heading)
    replaced by the generated one."""
    groups = {g.name: g for g in GROUPS}
    out, position = [], 0
    headings = list(HEADING.finditer(text))
    missing = set(groups) - {h[1] for h in headings}
    if missing:
        raise SystemExit(f"REFERENCE.md has no section for {sorted(missing)}")
    for heading in headings:
        table = TABLE.search(text, heading.end())
        if table is None:
            raise SystemExit(f"REFERENCE.md: no variable table after &{heading[1]}")
        out.append(text[position:table.start()])
        out.append(reference_table(groups[heading[1]]) + "\n")
        position = table.end()
    out.append(text[position:])
    return "".join(out)


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "fortran":
        Path(argv[1]).write_text(fortran_module())
        return 0
    if argv == ["reference"]:
        print("\n\n".join(f"## `&{g.name}`\n\n{reference_table(g)}" for g in GROUPS))
        return 0
    if len(argv) == 2 and argv[0] in ("check", "update"):
        path = Path(argv[1])
        text = path.read_text()
        wanted = with_tables(text)
        if argv[0] == "update":
            path.write_text(wanted)
            return 0
        if wanted != text:
            sys.stdout.writelines(difflib.unified_diff(
                text.splitlines(True), wanted.splitlines(True), str(path),
                "from variables.py"))
            return 1
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
