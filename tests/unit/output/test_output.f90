! SPDX-License-Identifier: MIT
!> Unit tests of the output names: state file names that never overflow and keep their
!> order, and the rule that decides which names a run may ever delete.
module test_output
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_error, only: error_type
    use yarnfort_output_vtk, only: get_state_name
    use yarnfort_output_manifest, only: is_own_name, is_state_name, is_bookkeeping_name
    implicit none
    private

    public :: collect_output

contains

    subroutine collect_output(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('state_names', test_state_names), &
            new_unittest('own_names', test_own_names), &
            new_unittest('bookkeeping_names', test_bookkeeping_names)]
    end subroutine collect_output

    !> Five digits up to step 99 999, then as many as needed; every name distinct and
    !> recognised as a state name.
    subroutine test_state_names(error)
        type(error_type), allocatable, intent(out) :: error
        integer, parameter :: steps(*) = [0, 7, 99998, 99999, 100000, 100001, 1234567, &
            huge(1)]
        character(len=*), parameter :: names(*) = [character(len=24) :: 'state_00000.vtu', &
            'state_00007.vtu', 'state_99998.vtu', 'state_99999.vtu', 'state_100000.vtu', &
            'state_100001.vtu', 'state_1234567.vtu', 'state_2147483647.vtu']
        integer :: i

        do i = 1, size(steps)
            call check(error, get_state_name(steps(i)) == trim(names(i)), &
                'state name of step ' // trim(names(i)) // ': ' // get_state_name(steps(i)))
            if (allocated(error)) return
            call check(error, is_state_name(get_state_name(steps(i))), &
                get_state_name(steps(i)) // ' is not taken as a state name')
            if (allocated(error)) return
        end do
    end subroutine test_state_names

    !> Only the fixed names of a run, state names and those of their blocks; nothing with a
    !> folder in it.
    subroutine test_own_names(error)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: own(*) = [character(len=24) :: 'curve.csv', &
            'input.nml', 'restart.dat', 'restart.dat.tmp', 'states.pvd', 'states.pvd.tmp', &
            'restart.sync', 'restart.sync.tmp', 'state_00012.vtu', 'state_123456.vtu', &
            'holders_00012.vtu', 'links_123456.vtu', 'passages_00000.vtu', 'state_00012.vtm']
        character(len=*), parameter :: foreign(*) = [character(len=24) :: 'notes.txt', &
            '../curve.csv', 'sub/state_00001.vtu', 'state_1.vtu', 'state_0000x.vtu', &
            'holders_1.vtu', 'links_0000x.vtu', 'passages_.vtu', 'passages.vtu', &
            'state_1.vtm', 'holders_00012.vtm', '.vtm', &
            'state_00001.vtu.bak', 'state_00001.vtk', '.yarnfort-lock', 'measured.csv', '']
        integer :: i

        do i = 1, size(own)
            call check(error, is_own_name(trim(own(i))), trim(own(i)) // ' is not own')
            if (allocated(error)) return
        end do
        do i = 1, size(foreign)
            call check(error, .not. is_own_name(trim(foreign(i))), "'" // trim(foreign(i)) &
                // "' is taken as a name of this program")
            if (allocated(error)) return
        end do
    end subroutine test_own_names

    !> The manifest, its temporary, the lock and the probe: checked for links like the
    !> files of a run, but never listed, so never deleted.
    subroutine test_bookkeeping_names(error)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: names(*) = [character(len=24) :: &
            '.yarnfort-manifest', '.yarnfort-manifest.tmp', '.yarnfort-lock', &
            '.yarnfort-write-test']
        integer :: i

        do i = 1, size(names)
            call check(error, is_bookkeeping_name(trim(names(i))) .and. &
                .not. is_own_name(trim(names(i))), trim(names(i)) // ' is not bookkeeping only')
            if (allocated(error)) return
        end do
        call check(error, .not. is_bookkeeping_name('curve.csv') .and. &
            .not. is_bookkeeping_name('.yarnfort-lock.tmp'), 'a run file taken as bookkeeping')
    end subroutine test_bookkeeping_names

end module test_output
