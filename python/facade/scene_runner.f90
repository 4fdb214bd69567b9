! SPDX-License-Identifier: MIT
!> Run a scene from a namelist file for the Python facade, writing the same files as the
!> program (curve.csv, VTK states, input.nml) but no progress lines, and counting the
!> converged steps. Kept out of `yarnfort_facade`, which f2py reads, because f2py cannot
!> parse derived types with type-bound procedures.
module yarnfort_facade_scene_runner
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_input_config, only: config_type
    use yarnfort_input_namelist, only: read_config_from_file, check_config
    use yarnfort_input_echo, only: write_config
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_output_writer, only: output_writer_type
    use yarnfort_driver, only: run_scene
    implicit none
    private

    public :: run_scene_from_file, status_input, status_solve

    !> Error status for bad input or an unusable output folder (the program's exit code).
    integer, parameter :: status_input = 2

    !> Error status for a failed solve, or an output error after it (the program's exit
    !> code); the converged steps are kept.
    integer, parameter :: status_solve = 1

    !> Longest I/O error message kept.
    integer, parameter :: iomsg_length = 512

    !> The library's file writer, silent, counting the converged steps it wrote.
    type, extends(output_writer_type) :: counting_writer_type
        !> Converged steps written so far (step 0, the initial equilibrium, included).
        integer :: n_steps = 0
    contains
        procedure :: on_step
    end type counting_writer_type

contains

    !> Read, check and build the scene in the namelist file `path`, then solve its load
    !> path writing the outputs to its &output folder (returned in `folder`). `n_steps`:
    !> converged steps written, the rows of curve.csv. Relative file names in the input are
    !> resolved against the folder of `path`, a relative &output folder against the working
    !> directory, as for `yarnfort < path`. With &control check_only nothing is solved or
    !> written. On failure `error%stat` is `status_input` or `status_solve` and the message
    !> starts with the stage (input, output, solve).
    subroutine run_scene_from_file(path, n_steps, folder, error)
        character(len=*), intent(in) :: path
        integer, intent(out) :: n_steps
        character(len=:), allocatable, intent(out) :: folder
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        type(scene_type), target :: scene
        type(counting_writer_type) :: writer
        type(error_type), allocatable :: finish_error

        n_steps = 0
        folder = ''
        call read_config_from_file(path, config, error)
        if (.not. allocated(error)) then
            folder = trim(config%output%folder)
            call check_config(config, error)
        end if
        if (.not. allocated(error)) call new_scene(scene, config, error)
        if (allocated(error)) then
            call set_stage(error, 'input', status_input)
            return
        end if
        if (config%control%check_only) return

        call writer%open(scene, error)
        if (.not. allocated(error)) call write_effective_input(config, error)
        if (allocated(error)) then
            call set_stage(error, 'output', status_input)
            return
        end if
        call run_scene(scene, writer, error)
        call writer%finish(scene, finish_error)
        n_steps = writer%n_steps
        if (allocated(error)) then
            call set_stage(error, 'solve', status_solve)
        else if (allocated(finish_error)) then
            call move_alloc(finish_error, error)
            call set_stage(error, 'output', status_solve)
        end if
    end subroutine run_scene_from_file

    !> Write the step with the parent writer; count it if that succeeded.
    subroutine on_step(self, scene, state, error)
        class(counting_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        call self%output_writer_type%on_step(scene, state, error)
        if (allocated(error)) return
        self%n_steps = self%n_steps + 1
    end subroutine on_step

    !> Echo the effective input to <folder>/input.nml, as the program does.
    subroutine write_effective_input(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: file
        character(len=iomsg_length) :: iomsg
        integer :: unit, stat

        file = trim(config%output%folder) // '/input.nml'
        open(newunit=unit, file=file, status='replace', action='write', iostat=stat, &
            iomsg=iomsg)
        if (stat /= 0) then
            call fatal_error(error, "cannot write '" // file // "': " // trim(iomsg))
            return
        end if
        call write_config(unit, config)
        close(unit)
    end subroutine write_effective_input

    !> Name the stage in front of the message and set the status.
    subroutine set_stage(error, stage, status)
        type(error_type), intent(inout) :: error
        character(len=*), intent(in) :: stage
        integer, intent(in) :: status

        call prefix_error(error, stage)
        error%stat = status
    end subroutine set_stage

end module yarnfort_facade_scene_runner
