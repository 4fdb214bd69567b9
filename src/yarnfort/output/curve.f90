! SPDX-License-Identifier: MIT
!> The curve file: one CSV row per converged step, flushed as soon as it is written
!> (a table_writer_type, resumed on restart).
module yarnfort_output_curve
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type, get_fabric_strain
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_output_csv_rows, only: csv_rows_type
    use yarnfort_scene_channels, only: get_curve_columns, curve_column_length
    use yarnfort_output_table, only: table_writer_type
    use yarnfort_output_membrane, only: get_membrane
    implicit none
    private

    public :: curve_writer_type, curve_file_name, get_support_displacement
    public :: get_load_displacement

    character(len=*), parameter :: curve_file_name = 'curve.csv'

    type, extends(table_writer_type) :: curve_writer_type
    contains
        procedure :: open => open_curve
        !> Keep the rows up to a step of an existing curve file and append after them.
        procedure :: resume => resume_curve
        procedure :: write_step
    end type curve_writer_type

contains

    !> Create folder/curve.csv and write its header. Columns: step, time, the factor of
    !> each load channel (p_force, p_disp without &path channels), then rx, ry, rz (N,
    !> force applied by the support on the net) for each support set, then ux, uy, uz (m,
    !> the mean displacement of the set's prescribed coordinates, per component; 0 for a
    !> component it does not prescribe) for each support set, then load_<k>_ux, _uy, _uz
    !> (m, the mean displacement of the nodes of &load #k) for each &load, then for a
    !> fabric strain and force_per_width, for a periodic cell e11, e22, gamma12, n11, n22,
    !> n12 (yarnfort_output_membrane), then direction (1 loading, -1 unloading, 0
    !> neither: sign of the change of the sum of the channels' factors), passages
    !> slipping, passages held in stick by chatter damping, 1 if the step ended in a jump
    !> after a slip instability (else 0), and sliding passages in all,
    !> Newton iterations of the step (all solves), final scaled residual, step cuts and
    !> wall time (s) of the step.
    subroutine open_curve(self, folder, scene, error)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error

        call self%open_table(folder, curve_file_name, get_header(scene), error)
    end subroutine open_curve

    !> Continue folder/curve.csv after `step` (a restart: resume_table with the header of
    !> `scene`). The row of `step` must have the pseudo-time `time` (that of the restart
    !> file), and the row of step - 1 (when step > 0 and the file has it) `previous_time`.
    subroutine resume_curve(self, folder, scene, step, error, time, previous_time)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: time, previous_time

        call self%resume_table(folder, curve_file_name, get_header(scene), step, error, time, &
            previous_time=previous_time)
    end subroutine resume_curve

    !> The header line of the curve file for `scene` (columns: see open_curve; the
    !> names of get_curve_columns, which the input check found unique).
    function get_header(scene) result(header)
        type(scene_type), intent(in) :: scene
        character(len=:), allocatable :: header
        character(len=curve_column_length), allocatable :: names(:)
        integer, allocatable :: kind(:), item(:)
        integer :: n_loads, j

        n_loads = 0
        if (allocated(scene%loads)) n_loads = size(scene%loads)
        call get_curve_columns(scene%path%channel, scene%supports%name, n_loads, &
            scene%fabric_set > 0, scene%periodic_cell, names, kind, item)
        header = trim(names(1))
        do j = 2, size(names)
            header = header // ',' // trim(names(j))
        end do
    end function get_header

    subroutine write_step(self, scene, state, error)
        class(curve_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error
        type(csv_rows_type) :: row
        integer :: s

        call row%add(state%step)
        call row%add(state%time)
        call row%add(state%factors)
        do s = 1, size(state%reaction, 2)
            call row%add(state%reaction(:, s))
        end do
        do s = 1, size(scene%supports)
            call row%add(get_support_displacement(scene, state, s))
        end do
        if (allocated(scene%loads)) then
            do s = 1, size(scene%loads)
                call row%add(get_load_displacement(scene, state, s))
            end do
        end if
        if (scene%fabric_set > 0) then
            call row%add(get_fabric_strain(scene, state%factors))
            call row%add(state%reaction(1, scene%fabric_set) / scene%fabric_width)
        end if
        if (scene%periodic_cell) call row%add(get_membrane(scene, state))
        call row%add(state%direction)
        call row%add(state%n_slipping)
        call row%add(state%n_held)
        call row%add(merge(1, 0, state%jump_steps > 0))
        call row%add(state%n_passages)
        call row%add(state%newton_iterations)
        call row%add(state%newton%residual_norm)
        call row%add(state%step_cuts)
        call row%add(state%wall_time)
        if (self%unit == -1) then
            call fatal_error(error, "cannot write '" // self%path // "': it is not open")
            return
        end if
        call self%put_line(row%get(), error)
    end subroutine write_step

    !> Mean displacement (m, from the initial position) of the coordinates support set s
    !> prescribes, per component (0 for a component it prescribes nowhere).
    pure function get_support_displacement(scene, state, s) result(displacement)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: s
        real(wp) :: displacement(3)
        integer :: i, c, k, node, n(3)

        displacement = 0.0_wp
        n = 0
        do i = 1, size(scene%supports(s)%coordinates)
            c = scene%supports(s)%coordinates(i)
            node = (c - 1) / 3 + 1
            k = c - 3 * (node - 1)
            displacement(k) = displacement(k) + (state%position(k, node) &
                - scene%network%position(k, node))
            n(k) = n(k) + 1
        end do
        where (n > 0) displacement = displacement / n
    end function get_support_displacement

    !> Mean displacement (m) of the nodes of &load #l.
    pure function get_load_displacement(scene, state, l) result(displacement)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: l
        real(wp) :: displacement(3)
        integer :: i, node

        displacement = 0.0_wp
        associate(nodes => scene%loads(l)%nodes)
            do i = 1, size(nodes)
                node = nodes(i)
                displacement = displacement + (state%position(:, node) &
                    - scene%network%position(:, node))
            end do
            if (size(nodes) > 0) displacement = displacement / size(nodes)
        end associate
    end function get_load_displacement

end module yarnfort_output_curve
