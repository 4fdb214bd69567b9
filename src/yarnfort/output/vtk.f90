! SPDX-License-Identifier: MIT
!> Network states as VTK XML unstructured grids for ParaView, and the states.pvd
!> collection listing them with their pseudo-time.
!>
!> A state is up to four blocks (files), so that colouring by any array shows only what
!> has it (ParaView draws a block without the array in one plain colour):
!> - state_NNNNN.vtu, the yarns: points the nodes (current positions), cells the yarn
!>   elements; point data displacement (from the initial position), position, and for
!>   scenes with sliding passages contact_state (0 no passage, 1 all stick, 2 a passage
!>   slips) and passages (their number at the node); cell data tension (N), stretch
!>   (current over reference length), L0 (reference length), yarn and material
!>   (1-based, input order);
!> - holders_NNNNN.vtu, links_NNNNN.vtu: the gap-holders and the periodic links
!>   (write_links);
!> - passages_NNNNN.vtu: one point per sliding passage (write_passages), so that two
!>   passages at one node both show.
!> Every block has the field data time, step, the factor of each load channel (p_force,
!> p_disp without &path channels), for a fabric strain and force_per_width, and for a
!> periodic cell e11 ... n12 (as in curve.csv). The multiblock file state_NNNNN.vtm lists
!> the blocks of a state by name (ParaView and VTK's XML multiblock reader open it as one
!> dataset), and states.pvd the multiblock files with their pseudo-time.
!> The files are built by yarnfort_output_vtu: appended base64-encoded binary by default,
!> or inline ASCII (&output vtk_format).
module yarnfort_output_vtk
    use, intrinsic :: iso_fortran_env, only: int8, int32, int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type, get_applied_force, get_fabric_strain
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_output_vtu, only: vtu_builder_type, start_vtu, finish_vtu, write_text_file, &
        add_text, add_reals, add_int32, vtk_vertex, vtk_line
    use yarnfort_text, only: format_integer
    use yarnfort_output_manifest, only: part_prefixes
    use yarnfort_output_contacts, only: passage_state_type, get_passage_states
    use yarnfort_output_membrane, only: membrane_names, get_membrane
    implicit none
    private

    public :: vtk_writer_type, get_state_name, get_part_name, get_multiblock_name
    public :: collection_file_name

    character(len=*), parameter :: collection_file_name = 'states.pvd'
    !> Longest state file name kept (get_state_name's are far shorter).
    integer, parameter :: state_name_length = 64

    type :: vtk_writer_type
        character(len=:), allocatable :: folder
        !> Inline ASCII data instead of appended base64 binary.
        logical :: ascii = .false.
        !> Files written so far (the first n_files entries; the arrays grow by doubling,
        !> so that adding one costs constant time on average) and their times.
        character(len=state_name_length), allocatable :: files(:)
        real(wp), allocatable :: times(:)
        integer :: n_files = 0
        !> Entries of states.pvd when it was last rewritten.
        integer :: listed = -1
        !> The blocks besides the yarns' that each state has (set_parts).
        logical :: has_part(3) = .false.
    contains
        !> Which blocks the states of a scene have.
        procedure, private :: set_parts
        procedure :: write_state
        !> Start the list of states anew with `files` and their `times`.
        procedure :: set_files
        !> Rewrite states.pvd (atomically) with every state written so far.
        procedure :: write_collection
    end type vtk_writer_type

    !> The blocks of a state besides the yarns', by their place in part_prefixes.
    integer, parameter :: part_holders = 1, part_links = 2, part_passages = 3
    !> The names of the blocks in a state's .vtm (ParaView's block tree), yarns first.
    character(len=*), parameter :: block_names(0:3) = [character(len=14) :: 'yarns', &
        'gap_holders', 'periodic_links', 'passages']
    integer, parameter :: contact_none = 0, contact_stick = 1, contact_slip = 2

    !> states.pvd is rewritten after a state when it then misses more than this fraction
    !> of the states (and always while it lists fewer than `collection_always`): the cost
    !> of the rewrites stays linear in the number of states.
    real(wp), parameter :: collection_lag = 0.05_wp
    integer, parameter :: collection_always = 100

contains

    !> The file name of the state of `step`: state_NNNNN.vtu, with as many digits as the
    !> step needs (at least 5), so that no number can overflow the field.
    pure function get_state_name(step) result(name)
        integer, intent(in) :: step
        character(len=:), allocatable :: name
        character(len=32) :: buffer
        write(buffer, '("state_", i0.5, ".vtu")') step
        name = trim(buffer)
    end function get_state_name

    !> The file name of block `part` (part_holders, part_links, part_passages) of the
    !> state file `name` (state_NNNNN.vtu): holders_NNNNN.vtu, links_..., passages_....
    pure function get_part_name(name, part) result(part_name)
        character(len=*), intent(in) :: name
        integer, intent(in) :: part
        character(len=:), allocatable :: part_name
        part_name = trim(part_prefixes(part)) // name(len('state_') + 1:)
    end function get_part_name

    !> The multiblock file of the state file `name` (state_NNNNN.vtu): state_NNNNN.vtm.
    pure function get_multiblock_name(name) result(multiblock_name)
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: multiblock_name
        multiblock_name = name(:len(name) - len('.vtu')) // '.vtm'
    end function get_multiblock_name

    !> Which blocks the states of `scene` have: gap-holders, periodic links, sliding
    !> passages.
    subroutine set_parts(self, scene)
        class(vtk_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        integer :: n_links

        n_links = 0
        if (allocated(scene%link_nodes)) n_links = size(scene%link_nodes, 2)
        self%has_part = .false.
        if (n_links > 0) then
            self%has_part(part_holders) = any(scene%link_is_gap)
            self%has_part(part_links) = .not. all(scene%link_is_gap)
        end if
        self%has_part(part_passages) = scene%passages%size() > 0
    end subroutine set_parts

    !> Write the files of `state` (`mode`, `flow`: stick/slip mode and flow of each
    !> passage, may be empty): its blocks and the multiblock file that lists them first,
    !> the yarns' state file last (a whole state file means a whole state), then
    !> states.pvd when due (collection_lag). A failed write removes the incomplete file
    !> and says why.
    subroutine write_state(self, scene, state, mode, flow, error)
        class(vtk_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        real(wp), intent(in) :: flow(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: name

        name = get_state_name(state%step)
        call self%set_parts(scene)
        if (self%has_part(part_holders) .or. self%has_part(part_links)) then
            call write_links(self, scene, state, name, error)
            if (allocated(error)) return
        end if
        if (self%has_part(part_passages)) then
            call write_passages(self, scene, state, mode, flow, &
                self%folder // '/' // get_part_name(name, part_passages), error)
            if (allocated(error)) return
        end if
        call write_multiblock(self, name, error)
        if (allocated(error)) return
        call write_yarns(self, scene, state, mode, self%folder // '/' // name, error)
        if (allocated(error)) return

        call add_file(self, name, state%time)
        if (self%n_files <= collection_always .or. &
                real(self%n_files - self%listed, wp) > collection_lag * self%n_files) &
            call self%write_collection(error)
    end subroutine write_state

    !> The multiblock file of the state file `name` (state_NNNNN.vtm): its blocks by
    !> name (block_names), the yarns first, so that ParaView shows each in its tree.
    subroutine write_multiblock(self, name, error)
        class(vtk_writer_type), intent(in) :: self
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: text
        integer :: part, index

        text = '<?xml version="1.0"?>' // new_line('a') &
            // '<VTKFile type="vtkMultiBlockDataSet" version="1.0">' // new_line('a') &
            // '<vtkMultiBlockDataSet>' // new_line('a') &
            // '<DataSet index="0" name="' // trim(block_names(0)) // '" file="' // name &
            // '"/>' // new_line('a')
        index = 0
        do part = 1, size(self%has_part)
            if (.not. self%has_part(part)) cycle
            index = index + 1
            text = text // '<DataSet index="' // format_integer(index) // '" name="' &
                // trim(block_names(part)) // '" file="' // get_part_name(name, part) // '"/>' &
                // new_line('a')
        end do
        text = text // '</vtkMultiBlockDataSet>' // new_line('a') // '</VTKFile>' &
            // new_line('a')
        call write_text_file(self%folder // '/' // get_multiblock_name(name), text, error)
    end subroutine write_multiblock

    !> The yarns' block (state_NNNNN.vtu): the nodes and the yarn elements.
    subroutine write_yarns(self, scene, state, mode, path, error)
        class(vtk_writer_type), intent(in) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        type(vtu_builder_type) :: vtu
        integer :: n_nodes, n_elements, e, p, node, y
        integer(int64), allocatable :: connectivity(:)
        integer(int32), allocatable :: yarn(:), contact(:), count(:)

        n_nodes = size(state%position, 2)
        n_elements = size(state%tension)
        allocate(connectivity(2 * n_elements), yarn(n_elements))
        do e = 1, n_elements
            connectivity(2 * e - 1:2 * e) = scene%network%element_nodes(:, e) - 1
        end do
        do y = 1, scene%network%n_yarns()
            yarn(scene%network%yarn_first_element(y):scene%network%yarn_first_element(y + 1) &
                - 1) = y
        end do
        call start_file(vtu, self%ascii, scene, state, n_nodes, n_elements)
        call add_text(vtu, '<PointData Vectors="displacement">')
        call add_reals(vtu, 'displacement', &
            reshape(state%position - scene%network%position, [3 * n_nodes]), 3)
        call add_reals(vtu, 'position', reshape(state%position, [3 * n_nodes]), 3)
        if (scene%passages%size() > 0) then
            allocate(contact(n_nodes), source=int(contact_none, int32))
            allocate(count(n_nodes), source=0_int32)
            do p = 1, scene%passages%size()
                node = scene%passages%node(p)
                count(node) = count(node) + 1
                if (contact(node) == contact_none) contact(node) = contact_stick
                if (p <= size(mode)) then
                    if (mode(p) /= 0) contact(node) = contact_slip
                end if
            end do
            call add_int32(vtu, 'contact_state', contact)
            call add_int32(vtu, 'passages', count)
        end if
        call add_text(vtu, '</PointData>')
        call add_text(vtu, '<CellData Scalars="tension">')
        call add_reals(vtu, 'tension', state%tension, 1)
        call add_reals(vtu, 'stretch', state%stretch, 1)
        call add_reals(vtu, 'L0', state%length0, 1)
        call add_int32(vtu, 'yarn', yarn)
        call add_int32(vtu, 'material', int(scene%network%element_material, int32))
        call add_text(vtu, '</CellData>')
        call finish_vtu(vtu, state%position, connectivity, vtk_line, 2, path, error)
    end subroutine write_yarns

    !> The links' blocks. holders_NNNNN.vtu: each gap-holder a line from its leader to
    !> its follower, or to the follower's image next to the leader when it holds the gap
    !> to a periodic image (follower minus period), with cell data contact_force (N: the
    !> force it pushes the follower away from the leader with, along the line; negative
    !> when it pulls), force (the vector on the follower, N), stretch, L0, period, leader
    !> and follower. links_NNNNN.vtu: each periodic link a vertex at the follower (the
    !> leader's image; a line would lie along the yarn it continues), cell data period,
    !> leader and follower. Node numbers 1-based.
    subroutine write_links(self, scene, state, name, error)
        class(vtk_writer_type), intent(in) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        type(vtu_builder_type) :: vtu
        integer :: n_links, n_nodes, l, k, n, e, r
        integer, allocatable :: chosen(:), link_of(:)
        integer(int64), allocatable :: connectivity(:)
        real(wp), allocatable :: net(:, :), carried(:, :), period(:, :), points(:, :), &
            applied(:), along(:), stretch(:), length0(:)
        real(wp) :: p_disp, now(3), before(3), pull(3)
        logical :: gap

        n_links = size(scene%link_nodes, 2)
        n_nodes = size(state%position, 2)
        p_disp = 0.0_wp
        if (scene%dofs%gap_channel >= 1 .and. scene%dofs%gap_channel <= size(state%factors)) &
            p_disp = state%factors(scene%dofs%gap_channel)
        allocate(period(3, n_links))
        do l = 1, n_links
            period(:, l) = scene%link_period(:, l) * (1.0_wp + p_disp * scene%link_strain(:, l))
            period(1, l) = period(1, l) + p_disp * scene%cell_shear * scene%link_period(2, l)
        end do
        ! The force a link carries: what acts on its follower's node (element tensions,
        ! applied load) and on the nodes that follow that node, down the chain of links.
        allocate(applied(3 * n_nodes))
        call get_applied_force(scene, state%factors, applied)
        net = reshape(applied, [3, n_nodes])
        do e = 1, size(state%tension)
            associate(ends => scene%network%element_nodes(:, e))
                pull = state%position(:, ends(2)) - state%position(:, ends(1))
                if (norm2(pull) > 0.0_wp) pull = state%tension(e) * pull / norm2(pull)
                net(:, ends(1)) = net(:, ends(1)) + pull
                net(:, ends(2)) = net(:, ends(2)) - pull
            end associate
        end do
        allocate(link_of(n_nodes), source=0)
        do l = 1, n_links
            link_of(scene%link_nodes(2, l)) = l
        end do
        allocate(carried(3, n_links), source=0.0_wp)
        do n = 1, n_nodes
            r = n
            k = 0
            do while (link_of(r) /= 0 .and. k < n_links)
                carried(:, link_of(r)) = carried(:, link_of(r)) + net(:, n)
                r = scene%link_nodes(1, link_of(r))
                k = k + 1
            end do
        end do

        do k = 1, 2
            gap = k == 1
            if (.not. self%has_part(merge(part_holders, part_links, gap))) cycle
            chosen = pack([(l, l = 1, n_links)], scene%link_is_gap .eqv. gap)
            if (gap) then
                allocate(points(3, 2 * size(chosen)), connectivity(2 * size(chosen)))
                allocate(along(size(chosen)), stretch(size(chosen)), length0(size(chosen)))
                do l = 1, size(chosen)
                    associate(pair => scene%link_nodes(:, chosen(l)))
                        points(:, 2 * l - 1) = state%position(:, pair(1))
                        points(:, 2 * l) = state%position(:, pair(2)) - period(:, chosen(l))
                        now = points(:, 2 * l) - points(:, 2 * l - 1)
                        before = scene%network%position(:, pair(2)) &
                            - scene%link_period(:, chosen(l)) - scene%network%position(:, pair(1))
                        length0(l) = norm2(before)
                        stretch(l) = 1.0_wp
                        if (length0(l) > 0.0_wp) stretch(l) = norm2(now) / length0(l)
                        ! The link balances the follower: it pushes with -carried.
                        along(l) = 0.0_wp
                        if (norm2(now) > 0.0_wp) &
                            along(l) = -dot_product(carried(:, chosen(l)), now) / norm2(now)
                    end associate
                end do
                connectivity = [(int(l, int64), l = 0, 2 * size(chosen) - 1)]
            else
                allocate(points(3, size(chosen)), connectivity(size(chosen)))
                do l = 1, size(chosen)
                    points(:, l) = state%position(:, scene%link_nodes(2, chosen(l)))
                end do
                connectivity = [(int(l, int64), l = 0, size(chosen) - 1)]
            end if
            call start_file(vtu, self%ascii, scene, state, size(points, 2), size(chosen))
            if (gap) then
                call add_text(vtu, '<CellData Scalars="contact_force">')
                call add_reals(vtu, 'contact_force', along, 1)
                call add_reals(vtu, 'force', reshape(-carried(:, chosen), &
                    [3 * size(chosen)]), 3)
                call add_reals(vtu, 'stretch', stretch, 1)
                call add_reals(vtu, 'L0', length0, 1)
            else
                call add_text(vtu, '<CellData>')
            end if
            call add_reals(vtu, 'period', reshape(period(:, chosen), [3 * size(chosen)]), 3)
            call add_int32(vtu, 'leader', int(scene%link_nodes(1, chosen), int32))
            call add_int32(vtu, 'follower', int(scene%link_nodes(2, chosen), int32))
            call add_text(vtu, '</CellData>')
            if (gap) then
                call finish_vtu(vtu, points, connectivity, vtk_line, 2, self%folder // '/' &
                    // get_part_name(name, part_holders), error)
            else
                call finish_vtu(vtu, points, connectivity, vtk_vertex, 1, self%folder // '/' &
                    // get_part_name(name, part_links), error)
            end if
            if (allocated(error)) return
            deallocate(points, connectivity)
        end do
    end subroutine write_links

    !> The passages' block (passages_NNNNN.vtu): one vertex per sliding passage at its
    !> node, with point data passage, node, yarn (1-based), mode (1 stick, 2 forward,
    !> 3 backward, 4 locked; 0 when the step has no friction state), flow,
    !> tension_min, tension_max, critical_tension and wrap_angle (as in contacts.csv).
    subroutine write_passages(self, scene, state, mode, flow, path, error)
        class(vtk_writer_type), intent(in) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        real(wp), intent(in) :: flow(:)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        type(vtu_builder_type) :: vtu
        type(passage_state_type) :: ps
        integer :: n, p
        integer, allocatable :: nodes(:)

        n = scene%passages%size()
        nodes = [(scene%passages%node(p), p = 1, n)]
        if (size(mode) == n .and. size(flow) == n) then
            call get_passage_states(scene, state, mode, flow, ps)
        else
            allocate(ps%mode(n), source=0)
            allocate(ps%flow(n), ps%tension_min(n), ps%tension_max(n), ps%critical(n), &
                ps%angle(n), source=0.0_wp)
        end if
        call start_file(vtu, self%ascii, scene, state, n, n)
        call add_text(vtu, '<PointData Scalars="mode">')
        call add_int32(vtu, 'passage', [(int(p, int32), p = 1, n)])
        call add_int32(vtu, 'node', int(nodes, int32))
        call add_int32(vtu, 'yarn', [(int(scene%passages%yarn(p), int32), p = 1, n)])
        call add_int32(vtu, 'mode', int(ps%mode, int32))
        call add_reals(vtu, 'flow', ps%flow, 1)
        call add_reals(vtu, 'tension_min', ps%tension_min, 1)
        call add_reals(vtu, 'tension_max', ps%tension_max, 1)
        call add_reals(vtu, 'critical_tension', ps%critical, 1)
        call add_reals(vtu, 'wrap_angle', ps%angle, 1)
        call add_text(vtu, '</PointData>')
        call finish_vtu(vtu, state%position(:, nodes), [(int(p, int64), p = 0, n - 1)], &
            vtk_vertex, 1, path, error)
    end subroutine write_passages

    !> Begin a file: the XML header, the field data (time, step, the load factors, a
    !> fabric's strain and force per width, a periodic cell's membrane strains and forces) and the piece of `n_points` and `n_cells`.
    subroutine start_file(vtu, ascii, scene, state, n_points, n_cells)
        type(vtu_builder_type), intent(out) :: vtu
        logical, intent(in) :: ascii
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: n_points, n_cells
        integer :: l
        real(wp) :: membrane(6)

        call start_vtu(vtu, ascii)
        call add_text(vtu, '<FieldData>')
        call add_reals(vtu, 'time', [state%time], 1, field=.true.)
        call add_int32(vtu, 'step', [int(state%step, int32)], field=.true.)
        do l = 1, size(state%factors)
            call add_reals(vtu, trim(scene%path%channel(l)), [state%factors(l)], 1, &
                field=.true.)
        end do
        if (scene%fabric_set > 0) then
            call add_reals(vtu, 'strain', [get_fabric_strain(scene, state%factors)], 1, &
                field=.true.)
            call add_reals(vtu, 'force_per_width', &
                [state%reaction(1, scene%fabric_set) / scene%fabric_width], 1, field=.true.)
        end if
        if (scene%periodic_cell) membrane = get_membrane(scene, state)
        do l = 1, merge(size(membrane_names), 0, scene%periodic_cell)
            call add_reals(vtu, trim(membrane_names(l)), [membrane(l)], 1, field=.true.)
        end do
        call add_text(vtu, '</FieldData>')
        call add_text(vtu, '<Piece NumberOfPoints="' // format_integer(n_points) &
            // '" NumberOfCells="' // format_integer(n_cells) // '">')
    end subroutine start_file

    subroutine set_files(self, files, times)
        class(vtk_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: files(:)
        real(wp), intent(in) :: times(:)
        integer :: i

        if (allocated(self%files)) deallocate(self%files, self%times)
        allocate(self%files(max(size(files), 16)), self%times(max(size(files), 16)))
        self%n_files = 0
        do i = 1, size(files)
            call add_file(self, files(i), times(i))
        end do
    end subroutine set_files

    !> Append a state file to the list, doubling the arrays when they are full.
    subroutine add_file(self, name, time)
        class(vtk_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: name
        real(wp), intent(in) :: time
        character(len=state_name_length), allocatable :: files(:)
        real(wp), allocatable :: times(:)

        if (.not. allocated(self%files)) allocate(self%files(16), self%times(16))
        if (self%n_files == size(self%files)) then
            allocate(files(2 * size(self%files)), times(2 * size(self%files)))
            files(:self%n_files) = self%files(:self%n_files)
            times(:self%n_files) = self%times(:self%n_files)
            call move_alloc(files, self%files)
            call move_alloc(times, self%times)
        end if
        self%n_files = self%n_files + 1
        self%files(self%n_files) = name
        self%times(self%n_files) = time
    end subroutine add_file

    !> Write states.pvd.tmp and rename it over states.pvd: each state's multiblock file
    !> with its pseudo-time. The text is built in one buffer sized for every entry, so a
    !> rewrite costs time linear in its entries.
    subroutine write_collection(self, error)
        class(vtk_writer_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: head = '<?xml version="1.0"?>' // achar(10) &
            // '<VTKFile type="Collection" version="0.1">' // achar(10) // '<Collection>' &
            // achar(10)
        character(len=*), parameter :: tail = '</Collection></VTKFile>' // achar(10)
        character(len=*), parameter :: before_time = '<DataSet timestep="', &
            before_file = '" file="', after_file = '"/>' // achar(10)
        !> The longest entry: its fixed text, a time (es24.16e3) and a file name.
        integer, parameter :: entry_length = len(before_time) + 24 + len(before_file) &
            + state_name_length + len(after_file)
        character(len=:), allocatable :: text
        character(len=24) :: time
        integer :: i, used

        allocate(character(len=len(head) + entry_length * self%n_files + len(tail)) :: text)
        used = 0
        call put(head)
        do i = 1, self%n_files
            write(time, '(es24.16e3)') self%times(i)
            call put(before_time)
            call put(trim(adjustl(time)))
            call put(before_file)
            call put(get_multiblock_name(trim(self%files(i))))
            call put(after_file)
        end do
        call put(tail)
        call write_text_file(self%folder // '/' // collection_file_name, text(:used), error, &
            atomic=.true.)
        if (allocated(error)) return
        self%listed = self%n_files
    contains
        subroutine put(piece)
            character(len=*), intent(in) :: piece
            text(used + 1:used + len(piece)) = piece
            used = used + len(piece)
        end subroutine put
    end subroutine write_collection

end module yarnfort_output_vtk
