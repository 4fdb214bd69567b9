! SPDX-License-Identifier: MIT
!> The program's step observer: the library's file writer plus progress lines on stderr.
module yarnfort_app_progress
    use, intrinsic :: iso_fortran_env, only: error_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_text, only: format_short
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_output_writer, only: output_writer_type
    use yarnfort_solver_membrane, only: get_membrane, get_frame_shear
    implicit none
    private

    public :: progress_writer_type

    type, extends(output_writer_type) :: progress_writer_type
        logical :: progress = .true.
        logical :: residual_history = .false.
        !> Steps of this run that ended in a jump (named at the end, progress or not).
        integer :: n_jumps = 0
        !> A sheared periodic cell: the largest shear in the yarns' frame and the largest
        !> n11, n22 over the run (N/m), for the note on its shear stiffness.
        real(wp) :: frame_shear = 0.0_wp, membrane_force = 0.0_wp
    contains
        procedure :: on_step
        procedure :: on_cut
        procedure :: on_resume
    end type progress_writer_type

contains

    subroutine on_step(self, scene, state, error)
        class(progress_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        integer :: c, k

        call self%output_writer_type%on_step(scene, state, error)
        if (allocated(error)) return
        if (state%jump_steps > 0) self%n_jumps = self%n_jumps + 1
        if (scene%periodic_cell .and. scene%cell_shear /= 0.0_wp) then
            block
                real(wp) :: values(6)
                values = get_membrane(scene, state)
                self%frame_shear = max(self%frame_shear, abs(get_frame_shear(values)))
                self%membrane_force = max(self%membrane_force, maxval(abs(values(4:5))))
            end block
        end if
        if (.not. self%progress) return
        write(error_unit, '("step ", i5, "  t = ", a)', advance='no') state%step, &
            fixed(state%time, '(f9.5)')
        ! The factor of every load channel (p_force and p_disp without &path channels).
        do c = 1, size(state%factors)
            write(error_unit, '("  ", a, " = ", a)', advance='no') &
                trim(scene%path%channel(c)), fixed(state%factors(c), '(f8.4)')
        end do
        write(error_unit, '("  newton ", a, "  residual ", a, "  ", a, " s")', &
            advance='no') fixed_count(state%newton_iterations), &
            format_short(state%newton%residual_norm), fixed(state%wall_time, '(f8.3)')
        if (state%n_passages > 0) then
            write(error_unit, '("  slipping ", i0, "/", i0)', advance='no') state%n_slipping, &
                state%n_passages
            ! Passages held in stick by chatter damping: rare, so named only when present.
            if (state%n_held > 0) write(error_unit, '("  held ", i0)', advance='no') &
                state%n_held
            ! A jump after a slip instability (try_jump), likewise.
            if (state%jump_steps > 0) write(error_unit, '("  jumped (", i0, &
                &" viscous steps)")', advance='no') state%jump_steps
            write(error_unit, '()')
        else
            write(error_unit, '()')
        end if
        if (self%residual_history) write(error_unit, '("  residuals", *(1x, a))') &
            (format_short(state%newton%residual_history(k)), &
            k = 1, size(state%newton%residual_history))
    end subroutine on_step

    subroutine on_cut(self, time, step, reason)
        class(progress_writer_type), intent(inout) :: self
        real(wp), intent(in) :: time, step
        character(len=*), intent(in) :: reason

        if (.not. self%progress) return
        write(error_unit, '("  cut: step of ", a, " from t = ", f9.5, " failed: ", a)') &
            format_short(step), time, reason
    end subroutine on_cut

    subroutine on_resume(self, step, time)
        class(progress_writer_type), intent(inout) :: self
        integer, intent(in) :: step
        real(wp), intent(in) :: time

        write(error_unit, '(a, i0, a, g0.6)') 'yarnfort: restarting after step ', step, &
            ' at t = ', time
    end subroutine on_resume

    !> `value` in the fixed edit descriptor `edit` (the columns line up), or in short
    !> exponent form where it does not fit (never a field of asterisks).
    function fixed(value, edit) result(text)
        real(wp), intent(in) :: value
        character(len=*), intent(in) :: edit
        character(len=:), allocatable :: text
        character(len=32) :: buffer

        write(buffer, edit) value
        if (index(buffer, '*') > 0) then
            text = format_short(value)
        else
            text = trim(buffer)
        end if
    end function fixed

    !> A count right-aligned in three columns, wider where it needs more.
    function fixed_count(count) result(text)
        integer, intent(in) :: count
        character(len=:), allocatable :: text
        character(len=16) :: buffer

        write(buffer, '(i0)') count
        text = repeat(' ', max(0, 3 - len_trim(buffer))) // trim(buffer)
    end function fixed_count

end module yarnfort_app_progress
