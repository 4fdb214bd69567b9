! SPDX-License-Identifier: MIT
!> The curve file: one CSV row per converged step, flushed as soon as it is written.
module yarnfort_output_curve
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    implicit none
    private

    public :: curve_writer_type, curve_file_name

    character(len=*), parameter :: curve_file_name = 'curve.csv'

    type :: curve_writer_type
        integer :: unit = -1
    contains
        procedure :: open => open_curve
        procedure :: write_step
        procedure :: close => close_curve
    end type curve_writer_type

contains

    !> Create folder/curve.csv and write its header. Columns: step, time, p_force,
    !> p_disp, then rx, ry, rz (N, force applied by the support on the net) for each
    !> support set, then direction (1 loading, -1 unloading, 0 neither: sign of the
    !> change of p_force + p_disp), passages slipping and sliding passages in all,
    !> Newton iterations of the step (all solves), final scaled residual, step cuts and
    !> wall time (s) of the step.
    subroutine open_curve(self, folder, scene, error)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error
        integer :: status, s
        character(len=:), allocatable :: header, name

        open(newunit=self%unit, file=folder // '/' // curve_file_name, status='replace', &
            action='write', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // folder // '/' // curve_file_name // "'")
            return
        end if
        header = 'step,time,p_force,p_disp'
        do s = 1, size(scene%supports)
            name = trim(scene%supports(s)%name)
            header = header // ',' // name // '_rx,' // name // '_ry,' // name // '_rz'
        end do
        header = header // ',direction,slipping,passages,newton_iterations,residual,step_cuts,wall_time'
        write(self%unit, '(a)') header
        flush(self%unit)
    end subroutine open_curve

    subroutine write_step(self, state)
        class(curve_writer_type), intent(inout) :: self
        type(step_state_type), intent(in) :: state
        character(len=32) :: field
        character(len=:), allocatable :: row
        integer :: s, k

        write(field, '(i0)') state%step
        row = trim(field)
        call append(state%time)
        call append(state%p_force)
        call append(state%p_disp)
        do s = 1, size(state%reaction, 2)
            do k = 1, 3
                call append(state%reaction(k, s))
            end do
        end do
        write(field, '(i0, ",", i0, ",", i0, ",", i0)') state%direction, state%n_slipping, &
            state%n_passages, state%newton_iterations
        row = row // ',' // trim(field)
        call append(state%newton%residual_norm)
        write(field, '(i0)') state%step_cuts
        row = row // ',' // trim(field)
        call append(state%wall_time)
        write(self%unit, '(a)') row
        flush(self%unit)
    contains
        subroutine append(value)
            real(wp), intent(in) :: value
            write(field, '(es24.16e3)') value
            row = row // ',' // trim(adjustl(field))
        end subroutine append
    end subroutine write_step

    subroutine close_curve(self)
        class(curve_writer_type), intent(inout) :: self
        if (self%unit /= -1) close(self%unit)
        self%unit = -1
    end subroutine close_curve

end module yarnfort_output_curve
