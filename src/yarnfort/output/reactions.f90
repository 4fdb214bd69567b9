! SPDX-License-Identifier: MIT
!> The rows of reactions.csv (`&output node_reactions`): per converged step, the reaction
!> of every node of every support set, in long format, written by `reactions_writer_type`
!> (a table_writer_type: rows appended and flushed per step, resumed on restart).
module yarnfort_output_reactions
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_output_table, only: table_writer_type
    use yarnfort_output_csv_rows, only: csv_rows_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    implicit none
    private

    public :: reactions_writer_type, reactions_file_name, reactions_header, get_reaction_rows
    public :: has_constrained_nodes

    character(len=*), parameter :: reactions_file_name = 'reactions.csv'

    !> Columns: step, support set name, node id, force (N) the support applies on the node.
    character(len=*), parameter :: reactions_header = 'step,support,node,rx,ry,rz'

    type, extends(table_writer_type) :: reactions_writer_type
    contains
        procedure :: open => open_reactions
        !> Keep the rows up to a step of an existing reactions.csv and append after them.
        procedure :: resume => resume_reactions
        procedure :: write_step
    end type reactions_writer_type

contains

    !> Create folder/reactions.csv and write its header.
    subroutine open_reactions(self, folder, error)
        class(reactions_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(error_type), allocatable, intent(out) :: error

        call self%open_table(folder, reactions_file_name, reactions_header, error)
    end subroutine open_reactions

    !> Continue folder/reactions.csv after `step` (a restart); the step must have rows
    !> when `scene` has a constrained node.
    subroutine resume_reactions(self, folder, scene, step, error)
        class(reactions_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error

        call self%resume_table(folder, reactions_file_name, reactions_header, step, error, &
            row_required=has_constrained_nodes(scene))
    end subroutine resume_reactions

    !> Append the rows of `state` (none when the scene has no constrained node).
    subroutine write_step(self, scene, state, error)
        class(reactions_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error

        if (has_constrained_nodes(scene)) call self%put_line(get_reaction_rows(scene, state), &
            error)
    end subroutine write_step

    !> Whether any support set prescribes a coordinate (reactions.csv has rows).
    pure logical function has_constrained_nodes(scene)
        type(scene_type), intent(in) :: scene
        integer :: s

        has_constrained_nodes = .false.
        do s = 1, size(scene%supports)
            if (size(scene%supports(s)%coordinates) > 0) has_constrained_nodes = .true.
        end do
    end function has_constrained_nodes

    !> The rows of one step, joined by newlines (no newline after the last), or '' if the
    !> scene has no constrained node. One row per node of each set, in the order of the
    !> set's coordinates; components the set does not fix are 0.
    function get_reaction_rows(scene, state) result(rows)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        character(len=:), allocatable :: rows
        type(csv_rows_type) :: table
        real(wp) :: force(3)
        integer :: s, i, j, first, node, c
        logical, allocatable :: done(:)

        first = 0
        do s = 1, size(scene%supports)
            associate(coordinates => scene%supports(s)%coordinates)
                allocate(done(size(coordinates)), source=.false.)
                do i = 1, size(coordinates)
                    if (done(i)) cycle
                    node = (coordinates(i) - 1) / 3 + 1
                    force = 0.0_wp
                    do j = i, size(coordinates)
                        c = coordinates(j)
                        if ((c - 1) / 3 + 1 /= node) cycle
                        force(mod(c - 1, 3) + 1) = state%coordinate_reaction(first + j)
                        done(j) = .true.
                    end do
                    call table%new_row()
                    call table%add(state%step)
                    call table%add(trim(scene%supports(s)%name))
                    call table%add(node)
                    call table%add(force)
                end do
                first = first + size(coordinates)
                deallocate(done)
            end associate
        end do
        rows = table%get()
    end function get_reaction_rows

end module yarnfort_output_reactions
