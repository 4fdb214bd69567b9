! SPDX-License-Identifier: MIT
!> The step observer that writes a run's files: curve.csv after every converged step and
!> a VTK state every `vtk_every` steps (and always the last one written by `finish`).
module yarnfort_output_writer
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_observer_type, step_state_type
    use yarnfort_output_curve, only: curve_writer_type
    use yarnfort_output_vtk, only: vtk_writer_type
    use yarnfort_output_filesystem, only: make_folder
    implicit none
    private

    public :: output_writer_type

    type, extends(step_observer_type) :: output_writer_type
        character(len=:), allocatable :: folder
        integer :: vtk_every = 1
        type(curve_writer_type) :: curve
        type(vtk_writer_type) :: vtk
        !> The last state, kept to write it as VTK at the end when it was skipped.
        type(step_state_type) :: last
        logical :: last_written = .true.
    contains
        procedure :: open => open_writer
        procedure :: on_step
        procedure :: on_cut
        procedure :: finish
    end type output_writer_type

contains

    !> Create the output folder and the curve file.
    subroutine open_writer(self, scene, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error

        self%folder = trim(scene%output%folder)
        self%vtk_every = scene%output%vtk_every
        call make_folder(self%folder, error)
        if (allocated(error)) return
        self%vtk%folder = self%folder
        ! A rerun into the same folder must not leave states of the earlier run behind.
        call self%vtk%remove_previous()
        call self%curve%open(self%folder, scene, error)
    end subroutine open_writer

    subroutine on_step(self, scene, state, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        call self%curve%write_step(state)
        self%last_written = .true.
        if (self%vtk_every > 0) then
            if (mod(state%step, self%vtk_every) == 0) then
                call self%vtk%write_state(scene, state, error)
            else
                self%last = state
                self%last_written = .false.
            end if
        end if
    end subroutine on_step

    subroutine on_cut(self, time, step, reason)
        class(output_writer_type), intent(inout) :: self
        real(wp), intent(in) :: time, step
        character(len=*), intent(in) :: reason
    end subroutine on_cut

    !> Write the last converged state if it was skipped, and close the curve file.
    subroutine finish(self, scene, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error

        if (.not. self%last_written .and. self%vtk_every > 0) then
            call self%vtk%write_state(scene, self%last, error)
        end if
        call self%curve%close()
    end subroutine finish

end module yarnfort_output_writer
