! SPDX-License-Identifier: MIT
!> Unit tests of the units of table files: every unit's factor against the conversion by
!> hand, the units a column header states, and tables in lab units against the same
!> table written in SI by hand.
module test_table_units
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_units, only: unit_type, find_unit, to_scene_unit, get_header_unit
    use yarnfort_material_table, only: table_law_type, read_table_law, max_table_strain
    use yarnfort_friction_general, only: rate_table_type => table_law_type, read_rate_table
    implicit none
    private

    public :: collect_table_units

    !> Identities that hold up to rounding (relative).
    real(wp), parameter :: identity_tol = 100 * epsilon(1.0_wp)
    character(len=*), parameter :: lf = achar(10)
    character(len=*), parameter :: path = 'test_table_units.csv'

    !> One table in SI, rows (strain, force N), and the same table in % and cN, in
    !> permille and gf, and as an elongation in mm of a 250 mm specimen, in lbf.
    character(len=*), parameter :: si_rows = '0,0' // lf // '0.05,0.123' // lf &
        // '0.1,0.31' // lf // '0.2,0.9' // lf
    character(len=*), parameter :: percent_cn_rows = '0,0' // lf // '5,12.3' // lf &
        // '10,31' // lf // '20,90' // lf

contains

    !> Collect the tests of table units.
    subroutine collect_table_units(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('every unit converts as by hand', test_unit_factors), &
            new_unittest('unknown spellings are not units', test_unknown_units), &
            new_unittest('units a column header states', test_header_units), &
            new_unittest('table in % and cN equals the SI table', test_percent_cn_table), &
            new_unittest('units stated in &material', test_stated_units), &
            new_unittest('elongation over a gauge length', test_elongation_table), &
            new_unittest('plain headers and none: 1 and N', test_default_units), &
            new_unittest('bad units and misread strains refused', test_refused_tables), &
            new_unittest('units only in a note, header shapes, column names', &
                test_notes_and_names), &
            new_unittest('rate table in cN and cN/rad', test_rate_table_units) &
            ]
    end subroutine collect_table_units

    !> Each spelling against the value written in SI by hand: % = 1e-2, permille = 1e-3,
    !> cN = 1e-2 N, mN = 1e-3 N, kN = 1e3 N, gf = 9.80665e-3 N, kgf = 9.80665 N,
    !> lbf = 4.4482216152605 N, lengths to m. The power-of-ten ones are exact divisions,
    !> so they must give the correctly rounded double of the SI value.
    subroutine test_unit_factors(error)
        type(error_type), allocatable, intent(out) :: error

        call expect(error, '1', 0.37_wp, 0.37_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, '-', 0.37_wp, 0.37_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, '%', 5.0_wp, 0.05_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, '%', 12.5_wp, 0.125_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'permille', 7.0_wp, 0.007_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'Permille', 7.0_wp, 0.007_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, char(226) // char(128) // char(176), 7.0_wp, 0.007_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'N', 1.25_wp, 1.25_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'cN', 12.3_wp, 0.123_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'mN', 250.0_wp, 0.25_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'kN', 2.5_wp, 2500.0_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'gf', 1000.0_wp, 9.80665_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'gf', 2.0_wp, 0.0196133_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'GF', 2.0_wp, 0.0196133_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'kgf', 2.0_wp, 19.6133_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'lbf', 2.0_wp, 8.896443230521_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'LBF', 1.0_wp, 4.4482216152605_wp, identity_tol)
        if (allocated(error)) return
        call expect(error, 'm', 1.5_wp, 1.5_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'cm', 2.0_wp, 0.02_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'mm', 1500.0_wp, 1.5_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'mm', 3.0_wp, 0.003_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, 'um', 250.0_wp, 2.5e-4_wp, 0.0_wp)
        if (allocated(error)) return
        call expect(error, char(194) // char(181) // 'm', 250.0_wp, 2.5e-4_wp, 0.0_wp)
    end subroutine test_unit_factors

    !> Spellings that are no unit, or another one in another case (MN is a meganewton).
    subroutine test_unknown_units(error)
        type(error_type), allocatable, intent(out) :: error
        character(len=8), parameter :: unknown(*) = [character(len=8) :: 'MN', 'CN', 'n', &
            'pct', 'g', 'N/tex', 'MPa', 'inch', 'MM', '']
        type(unit_type) :: unit
        logical :: found
        integer :: i

        do i = 1, size(unknown)
            call find_unit(trim(unknown(i)), unit, found)
            call check(error, .not. found, "'" // trim(unknown(i)) // "' taken as a unit")
            if (allocated(error)) return
        end do
    end subroutine test_unknown_units

    !> The unit text of a header field: in (...) or [...], or a last word that is a unit.
    subroutine test_header_units(error)
        type(error_type), allocatable, intent(out) :: error

        call expect_header(error, 'Force (cN)', 'cN')
        if (allocated(error)) return
        call expect_header(error, ' Elongation (%) ', '%')
        if (allocated(error)) return
        call expect_header(error, 'strain [%]', '%')
        if (allocated(error)) return
        call expect_header(error, 'Force in cN', 'cN')
        if (allocated(error)) return
        call expect_header(error, 'Force/gf', 'gf')
        if (allocated(error)) return
        call expect_header(error, 'mm', 'mm')
        if (allocated(error)) return
        call expect_header(error, 'Force (cN) mean', 'cN')
        if (allocated(error)) return
        call expect_header(error, 'Stress (N/tex)', 'N/tex')
        if (allocated(error)) return
        call expect_header(error, 'strain ( % )', '%')
        if (allocated(error)) return
        call expect_header(error, 'strain', '')
        if (allocated(error)) return
        call expect_header(error, 'force', '')
        if (allocated(error)) return
        call expect_header(error, 'Maximum force', '')
    end subroutine test_header_units

    !> The issue's table, 'Elongation (%),Force (cN)', against the same rows divided by
    !> 100 by hand: the same knots to rounding (12.3 / 100 and 0.123 are each rounded
    !> once), so the same law.
    subroutine test_percent_cn_table(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: lab, si

        call read_pair(error, 'strain,force' // lf // si_rows, &
            'Elongation (%),Force (cN)' // lf // percent_cn_rows, si, lab)
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
        if (allocated(error)) return
        ! A units line of its own, after the names: 'Elongation,Force' then '%,cN'.
        call read_pair(error, 'strain,force' // lf // si_rows, &
            'Elongation,Force' // lf // '%,cN' // lf // percent_cn_rows, si, lab)
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
        if (allocated(error)) return
        call read_pair(error, 'strain,force' // lf // si_rows, &
            'Elongation,Force' // lf // '[%],[cN]' // lf // percent_cn_rows, si, lab)
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
        if (allocated(error)) return
        ! permille and gf: forces in gf written as F / 9.80665e-3 N by hand.
        call write_file(path, 'strain (permille), force (gf)' // lf // '0,0' // lf &
            // '50,' // real_text(0.123_wp / 9.80665e-3_wp) // lf &
            // '100,' // real_text(0.31_wp / 9.80665e-3_wp) // lf &
            // '200,' // real_text(0.9_wp / 9.80665e-3_wp) // lf)
        call read_expect_ok(error, lab)
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
    end subroutine test_percent_cn_table

    !> Units stated by &material strain_unit and force_unit instead of a header, and
    !> with a header that states the same.
    subroutine test_stated_units(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: lab, si
        type(error_type), allocatable :: law_error

        call write_file(path, 'strain,force' // lf // si_rows)
        call read_expect_ok(error, si)
        if (allocated(error)) return
        call write_file(path, percent_cn_rows)
        call read_table_law(lab, path, law_error, strain_unit='%', force_unit='cN')
        call check(error, .not. allocated(law_error), 'stated units refused')
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
        if (allocated(error)) return
        call write_file(path, 'Elongation (%),Force (cN)' // lf // percent_cn_rows)
        call read_table_law(lab, path, law_error, strain_unit='%', force_unit='cN')
        call check(error, .not. allocated(law_error), 'agreeing units refused')
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
    end subroutine test_stated_units

    !> Elongation in mm of a specimen 0.25 m long: strain = elongation / 250 mm.
    subroutine test_elongation_table(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: lab, si
        type(error_type), allocatable :: law_error

        call write_file(path, 'strain,force' // lf // si_rows)
        call read_expect_ok(error, si)
        if (allocated(error)) return
        call write_file(path, 'Extension (mm),Load (N)' // lf // '0,0' // lf &
            // '12.5,0.123' // lf // '25,0.31' // lf // '50,0.9' // lf)
        call read_table_law(lab, path, law_error, gauge_length=0.25_wp)
        call check(error, .not. allocated(law_error), 'elongation table refused')
        if (allocated(error)) return
        call same_law(error, lab, si, identity_tol)
    end subroutine test_elongation_table

    !> Today's tables: no header, or plain names, are strain 1 and force N.
    subroutine test_default_units(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: plain, bare

        call read_pair(error, 'strain,force' // lf // si_rows, si_rows, plain, bare)
        if (allocated(error)) return
        call check_close(error, plain%strain, [0.0_wp, 0.05_wp, 0.1_wp, 0.2_wp], 0.0_wp, &
            'strains of a plain header')
        if (allocated(error)) return
        call check_close(error, plain%force, [0.0_wp, 0.123_wp, 0.31_wp, 0.9_wp], 0.0_wp, &
            'forces of a plain header')
        if (allocated(error)) return
        call same_law(error, bare, plain, 0.0_wp)
        if (allocated(error)) return
        ! Only the last header line states units; a note before it does not.
        call write_file(path, 'Test of 2024-05-01 (lab 3), sample B' // lf // 'strain,force' &
            // lf // si_rows)
        call read_expect_ok(error, bare)
        if (allocated(error)) return
        call same_law(error, bare, plain, 0.0_wp)
    end subroutine test_default_units

    !> Lines before the rows whose units would not be read, and headers that name the
    !> columns otherwise than strain, force: refused with the line and column. Notes that
    !> record settings, or agree with the units read, leave the table as in SI.
    subroutine test_notes_and_names(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: plain, noted

        call expect_refused(error, '# Elongation (%),Force (cN)' // lf // percent_cn_rows, &
            [character(len=60) :: path, "line 1, column 1 ('Elongation (%)')", &
            "states the unit '%'", "read in '1'"])
        if (allocated(error)) return
        call expect_refused(error, 'Elongation (%),Force (cN)' // lf // 'sample 2' // lf &
            // percent_cn_rows, [character(len=60) :: "line 1, column 1", "read in '1'"])
        if (allocated(error)) return
        call expect_refused(error, 'Elongation,Force' // lf // '# %,cN' // lf &
            // percent_cn_rows, [character(len=60) :: "line 2, column 1 ('%')"])
        if (allocated(error)) return
        call expect_refused(error, 'Elongation (%),Force (cN),' // lf // percent_cn_rows, &
            [character(len=60) :: "line 1: the header states the unit '%'", &
            'not two comma-separated'])
        if (allocated(error)) return
        call expect_refused(error, 'Force,Strain' // lf // si_rows, &
            [character(len=60) :: "line 1, column 1 ('Force'): names a force"])
        if (allocated(error)) return
        call expect_refused(error, 'Strain,Tenacity' // lf // si_rows, &
            [character(len=60) :: "line 1, column 2 ('Tenacity'): names a quantity"])
        if (allocated(error)) return

        call write_file(path, 'strain,force' // lf // si_rows)
        call read_expect_ok(error, plain)
        if (allocated(error)) return
        ! Settings with values, units that agree with 1 and N, 'Extension' is not 'tension'.
        call write_file(path, '# gauge 500 mm, pretension 0.5 cN' // lf &
            // '# Strain (-),Force [N]' // lf // 'Extension,Tension' // lf // si_rows)
        call read_expect_ok(error, noted)
        if (allocated(error)) return
        call same_law(error, noted, plain, 0.0_wp)
    end subroutine test_notes_and_names

    !> Unknown units, wrong kinds, disagreements, gauge lengths and strains read in the
    !> wrong unit: each refused with the file, the line and the column.
    subroutine test_refused_tables(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        type(error_type), allocatable :: law_error

        call expect_refused(error, 'Elongation (%),Force (cn)' // lf // percent_cn_rows, &
            [character(len=60) :: path, 'line 1, column 2', "'cn' is not a known force unit", &
            "'cN'"])
        if (allocated(error)) return
        call expect_refused(error, 'Elongation (pct),Force (cN)' // lf // percent_cn_rows, &
            [character(len=60) :: 'line 1, column 1', "'pct' is not a known strain unit"])
        if (allocated(error)) return
        call expect_refused(error, 'Force (cN),Elongation (%)' // lf // percent_cn_rows, &
            [character(len=60) :: 'line 1, column 1', "'cN' is not a known strain unit"])
        if (allocated(error)) return
        call expect_refused(error, 'strain,Stress (MPa)' // lf // si_rows, &
            [character(len=60) :: 'line 1, column 2', "'MPa'"])
        if (allocated(error)) return
        ! The issue's table without units: 5 % read as a strain of 5 stays below the
        ! limit, but 20 % read as 20 does not.
        call expect_refused(error, 'Elongation,Force' // lf // percent_cn_rows, &
            [character(len=60) :: 'line 5, column 1', 'strain 20', "in '1'", 'exceeds 10'])
        if (allocated(error)) return
        call expect_refused(error, 'Extension (mm),Load (N)' // lf // '0,0' // lf &
            // '12.5,0.123' // lf, [character(len=60) :: path, 'elongation', &
            'gauge_length'])
        if (allocated(error)) return

        call write_file(path, 'Elongation (%),Force (cN)' // lf // percent_cn_rows)
        call read_table_law(law, path, law_error, force_unit='N')
        call check_error(law_error, [character(len=60) :: path, 'line 1, column 2', &
            "header states 'cN'", "force_unit = 'N'"], error)
        if (allocated(error)) return
        call read_table_law(law, path, law_error, gauge_length=0.25_wp)
        call check_error(law_error, [character(len=60) :: path, 'gauge_length', &
            "in '%'", 'not a length'], error)
        if (allocated(error)) return
        call write_file(path, percent_cn_rows)
        call read_table_law(law, path, law_error, strain_unit='percent')
        call check_error(law_error, [character(len=60) :: path, 'strain_unit', &
            "'percent' is not a known strain unit"], error)
        if (allocated(error)) return
        call write_file(path, 'Extension (mm),Load (N)' // lf // '0,0' // lf // '12.5,0.1' &
            // lf // '50,0.2' // lf)
        call read_table_law(law, path, law_error, gauge_length=4.0e-3_wp)
        call check_error(law_error, [character(len=60) :: path, 'line 4, column 1', &
            'strain 12.5', 'gauge length of 0.004 m'], error)
        if (allocated(error)) return
        call read_table_law(law, path, law_error, gauge_length=0.0_wp)
        call check_error(law_error, [character(len=60) :: path, 'gauge_length = 0', &
            'positive'], error)
        call delete_file(path)
        if (allocated(error)) return
        call check(error, max_table_strain == 10.0_wp, 'the documented limit is 10')
    end subroutine test_refused_tables

    !> A friction rate table in cN and cN/rad (and gf per radian) against the same in N and
    !> N/rad by hand; a unit that is not a force per radian is refused.
    subroutine test_rate_table_units(error)
        type(error_type), allocatable, intent(out) :: error
        type(rate_table_type) :: lab, si
        type(error_type), allocatable :: law_error

        call write_file(path, 'T,g' // lf // '0,0.05' // lf // '0.2,0.1' // lf // '0.4,0.3' // lf)
        call read_rate_table(si, path, law_error)
        call check(error, .not. allocated(law_error), 'SI rate table refused')
        if (allocated(error)) return
        call write_file(path, 'T (cN),g (cN/rad)' // lf // '0,5' // lf // '20,10' // lf &
            // '40,30' // lf)
        call read_rate_table(lab, path, law_error)
        call check(error, .not. allocated(law_error), 'rate table in cN refused')
        if (allocated(error)) return
        call check_close(error, lab%tension, si%tension, identity_tol, 'tensions')
        if (allocated(error)) return
        call check_close(error, lab%rate, si%rate, identity_tol, 'rates')
        if (allocated(error)) return
        call write_file(path, 'T [cN],g [gf]' // lf // '0,' // real_text(0.05_wp / 9.80665e-3_wp) &
            // lf // '20,' // real_text(0.1_wp / 9.80665e-3_wp) // lf // '40,' &
            // real_text(0.3_wp / 9.80665e-3_wp) // lf)
        call read_rate_table(lab, path, law_error)
        call check(error, .not. allocated(law_error), 'rate table in gf refused')
        if (allocated(error)) return
        call check_close(error, lab%rate, si%rate, identity_tol, 'rates in gf')
        if (allocated(error)) return
        call write_file(path, 'T (cN),g (cN/mm)' // lf // '0,5' // lf // '20,10' // lf)
        call read_rate_table(lab, path, law_error)
        call check_error(law_error, [character(len=60) :: path, 'line 1, column 2', &
            "'cN/mm' is not a known force unit per rad"], error)
        call delete_file(path)
    end subroutine test_rate_table_units

    !> The value `value` in unit `name` is `expected` in the scene's unit.
    subroutine expect(error, name, value, expected, tolerance)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: name
        real(wp), intent(in) :: value, expected, tolerance
        type(unit_type) :: unit
        logical :: found

        call find_unit(name, unit, found)
        call check(error, found, "unit '" // name // "' not found")
        if (allocated(error)) return
        call check_close(error, to_scene_unit(value, unit), expected, tolerance, &
            "a value in '" // name // "'")
    end subroutine expect

    !> The header field `field` states the unit `expected` ('' for none).
    subroutine expect_header(error, field, expected)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: field, expected
        character(len=:), allocatable :: text
        logical :: stated

        call get_header_unit(field, text, stated)
        call check(error, stated .eqv. len(expected) > 0, "header '" // field // "': " &
            // merge('a unit found   ', 'no unit found  ', stated))
        if (allocated(error) .or. .not. stated) return
        call check(error, text == expected, "header '" // field // "': unit '" // text &
            // "', expected '" // expected // "'")
    end subroutine expect_header

    !> Read the table files with the contents `first` and `second`.
    subroutine read_pair(error, first, second, first_law, second_law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: first, second
        type(table_law_type), intent(out) :: first_law, second_law

        call write_file(path, first)
        call read_expect_ok(error, first_law)
        if (allocated(error)) return
        call write_file(path, second)
        call read_expect_ok(error, second_law)
    end subroutine read_pair

    !> Read the test file, which must be a good table.
    subroutine read_expect_ok(error, law)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type), intent(out) :: law
        type(error_type), allocatable :: law_error

        call read_table_law(law, path, law_error)
        if (allocated(law_error)) then
            call check(error, .false., 'a good table refused: ' // law_error%message)
        end if
    end subroutine read_expect_ok

    !> The same knots and slopes, to `tolerance` (relative).
    subroutine same_law(error, law, reference, tolerance)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type), intent(in) :: law, reference
        real(wp), intent(in) :: tolerance

        call check(error, size(law%strain) == size(reference%strain), 'row counts differ')
        if (allocated(error)) return
        call check_close(error, law%strain, reference%strain, tolerance, 'strains')
        if (allocated(error)) return
        call check_close(error, law%force, reference%force, tolerance, 'forces')
        if (allocated(error)) return
        call check_close(error, law%slope, reference%slope, max(tolerance, identity_tol), &
            'slopes')
    end subroutine same_law

    !> The file with the contents `text` is refused with all of `words` in the message.
    subroutine expect_refused(error, text, words)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: text, words(:)
        type(table_law_type) :: law
        type(error_type), allocatable :: law_error

        call write_file(path, text)
        call read_table_law(law, path, law_error)
        call check_error(law_error, words, error)
    end subroutine expect_refused

    !> Fail unless `law_error` is set and contains every one of `words`.
    subroutine check_error(law_error, words, error)
        type(error_type), allocatable, intent(in) :: law_error
        character(len=*), intent(in) :: words(:)
        type(error_type), allocatable, intent(out) :: error
        integer :: i

        call check(error, allocated(law_error), 'expected an error containing "' &
            // trim(words(1)) // '", got none')
        if (allocated(error)) return
        do i = 1, size(words)
            call check(error, index(law_error%message, trim(words(i))) > 0, &
                'expected "' // trim(words(i)) // '" in the message: ' // law_error%message)
            if (allocated(error)) return
        end do
    end subroutine check_error

    !> A real written so that it reads back as the same double.
    function real_text(value) result(text)
        real(wp), intent(in) :: value
        character(len=:), allocatable :: text
        character(len=32) :: buffer

        write(buffer, '(es24.16e3)') value
        text = trim(adjustl(buffer))
    end function real_text

    !> Write `text` byte for byte (newlines as given) to `path`.
    subroutine write_file(name, text)
        character(len=*), intent(in) :: name, text
        integer :: unit

        open(newunit=unit, file=name, access='stream', form='unformatted', &
            status='replace', action='write')
        write(unit) text
        close(unit)
    end subroutine write_file

    !> Remove a file written by a test.
    subroutine delete_file(name)
        character(len=*), intent(in) :: name
        integer :: unit, stat

        open(newunit=unit, file=name, status='old', iostat=stat)
        if (stat == 0) close(unit, status='delete')
    end subroutine delete_file

end module test_table_units
