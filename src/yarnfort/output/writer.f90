! SPDX-License-Identifier: MIT
!> The step observer that writes a run's files: curve.csv after every converged step, a
!> VTK state every `vtk_every` steps (and always the last one written by `finish`), and
!> the restart file of every converged step.
module yarnfort_output_writer
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_observer_type, step_state_type
    use yarnfort_output_curve, only: curve_writer_type
    use yarnfort_output_vtk, only: vtk_writer_type
    use yarnfort_output_filesystem, only: make_folder
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_output_restart, only: write_restart, remove_restart
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
        !> Fingerprint of the input, stamped on the restart files (get_input_hash).
        character(len=16) :: input_hash = ''
    contains
        procedure :: open => open_writer
        procedure :: on_step
        procedure :: on_cut
        procedure :: on_checkpoint
        procedure :: finish
    end type output_writer_type

contains

    !> Create the output folder and the curve file; with `resume_step` (a restart),
    !> continue the folder's curve file and VTK states after that step instead.
    subroutine open_writer(self, scene, error, resume_step)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error
        integer, intent(in), optional :: resume_step

        self%folder = trim(scene%output%folder)
        self%vtk_every = scene%output%vtk_every
        call make_folder(self%folder, error)
        if (allocated(error)) return
        self%vtk%folder = self%folder
        if (present(resume_step)) then
            call self%curve%resume(self%folder, scene, resume_step, error)
            if (allocated(error)) return
            call self%vtk%resume(resume_step, error)
            return
        end if
        ! A rerun into the same folder must not leave states of the earlier run behind,
        ! nor its restart file.
        call self%vtk%remove_previous()
        call remove_restart(self%folder)
        call self%curve%open(self%folder, scene, error)
    end subroutine open_writer

    subroutine on_step(self, scene, state, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        call self%curve%write_step(scene, state)
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

    !> Write the restart file of the step just written.
    subroutine on_checkpoint(self, scene, snapshot, error)
        class(output_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error

        call write_restart(self%folder, snapshot, self%input_hash, error)
    end subroutine on_checkpoint

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
