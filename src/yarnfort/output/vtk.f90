! SPDX-License-Identifier: MIT
!> Network states as VTK XML unstructured grids (.vtu, one per written step) for
!> ParaView, and the states.pvd collection listing them with their pseudo-time.
!>
!> Each state holds the nodes (points: current positions) and, as cells, the yarn
!> elements followed by the links (gap-holders and periodic images, so that a fabric
!> shows connected). Arrays:
!> - field data: time, step, the factor of each load channel (p_force, p_disp without
!>   &path channels); for a fabric also strain and
!>   force_per_width (as in curve.csv);
!> - point data: displacement (from the initial position), position, and for scenes
!>   with sliding passages contact_state (0 no passage, 1 all stick, 2 a passage slips),
!>   passages (the number of sliding passages at the node), and the state of one of them
!>   (see write_state): passage (its number, 0 none), mode (0 none, 1 stick, 2 forward,
!>   3 backward, 4 locked), flow, tension_min, tension_max, critical_tension and
!>   wrap_angle (as in contacts.csv; 0 at nodes without a passage);
!> - cell data: kind (0 yarn element, 1 gap-holder, 2 periodic link), yarn and material
!>   (1-based, in input order; 0 for links), tension (N; 0 for links), stretch
!>   (current over reference length), L0 (reference length) and period (the current
!>   lattice vector a link spans: a periodic link's, a gap-holder's to a periodic
!>   image; zero for elements and links inside the cell).
!> The data are appended base64-encoded binary (VTK XML 1.0, UInt64 headers) by
!> default, or inline ASCII (&output vtk_format).
module yarnfort_output_vtk
    use, intrinsic :: iso_fortran_env, only: int8, int32, int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_output_filesystem, only: rename_file, remove_file, open_new_file, &
        close_new_file
    use yarnfort_text, only: format_integer
    use yarnfort_output_contacts, only: passage_state_type, get_passage_states
    implicit none
    private

    public :: vtk_writer_type, get_state_name, collection_file_name

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
    contains
        procedure :: write_state
        !> Start the list of states anew with `files` and their `times`.
        procedure :: set_files
        !> Rewrite states.pvd (atomically) with every state written so far.
        procedure :: write_collection
    end type vtk_writer_type

    integer(int8), parameter :: vtk_line = 3_int8
    integer, parameter :: kind_element = 0, kind_gap = 1, kind_periodic = 2
    integer, parameter :: contact_none = 0, contact_stick = 1, contact_slip = 2

    !> states.pvd is rewritten after a state when it then misses more than this fraction
    !> of the states (and always while it lists fewer than `collection_always`): the cost
    !> of the rewrites stays linear in the number of states.
    real(wp), parameter :: collection_lag = 0.05_wp
    integer, parameter :: collection_always = 100

    character(len=64), parameter :: base64_alphabet = &
        'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/'

    !> The XML text and appended data of one file being built.
    type :: vtu_builder_type
        logical :: ascii = .false.
        character(len=:), allocatable :: xml, appended
    end type vtu_builder_type

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

    !> Write the state file of `state` (`mode`, `flow`: stick/slip mode and flow of each
    !> passage, may be empty), then states.pvd when due (collection_lag). A failed write
    !> removes the incomplete state file and says why. A node with several passages shows
    !> the one that matters most for stick/slip: a slipping one (forward or backward)
    !> before a locked one before a stick one, and among those the one with the largest
    !> tension_max (the first in passage order on a tie); `passages` tells how many there
    !> are and contact_state whether any slips.
    subroutine write_state(self, scene, state, mode, flow, error)
        class(vtk_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:)
        real(wp), intent(in) :: flow(:)
        type(error_type), allocatable, intent(out) :: error
        type(vtu_builder_type) :: vtu
        character(len=:), allocatable :: name, path
        integer :: n_nodes, n_elements, n_links, n_cells, e, l, p, node, y
        integer(int64), allocatable :: connectivity(:), offsets(:)
        integer(int32), allocatable :: cell_kind(:), yarn(:), material(:), contact(:)
        real(wp), allocatable :: tension(:), stretch(:), length0(:), period(:, :)
        real(wp) :: now(3), before(3), p_disp

        name = get_state_name(state%step)
        path = self%folder // '/' // name
        n_nodes = size(state%position, 2)
        n_elements = size(state%tension)
        n_links = 0
        if (allocated(scene%link_nodes)) n_links = size(scene%link_nodes, 2)
        n_cells = n_elements + n_links

        allocate(connectivity(2 * n_cells), offsets(n_cells))
        allocate(cell_kind(n_cells), yarn(n_cells), material(n_cells))
        allocate(tension(n_cells), stretch(n_cells), length0(n_cells))
        allocate(period(3, n_cells), source=0.0_wp)
        p_disp = 0.0_wp
        if (scene%dofs%gap_channel >= 1 .and. scene%dofs%gap_channel <= size(state%factors)) &
            p_disp = state%factors(scene%dofs%gap_channel)
        do e = 1, n_elements
            connectivity(2 * e - 1:2 * e) = scene%network%element_nodes(:, e) - 1
        end do
        cell_kind(:n_elements) = kind_element
        do y = 1, scene%network%n_yarns()
            yarn(scene%network%yarn_first_element(y):scene%network%yarn_first_element(y + 1) &
                - 1) = y
        end do
        material(:n_elements) = scene%network%element_material
        tension(:n_elements) = state%tension
        stretch(:n_elements) = state%stretch
        length0(:n_elements) = state%length0
        do l = 1, n_links
            associate(pair => scene%link_nodes(:, l))
                e = n_elements + l
                connectivity(2 * e - 1:2 * e) = pair - 1
                cell_kind(e) = merge(kind_gap, kind_periodic, scene%link_is_gap(l))
                yarn(e) = 0
                material(e) = 0
                tension(e) = 0.0_wp
                now = state%position(:, pair(2)) - state%position(:, pair(1))
                before = scene%network%position(:, pair(2)) - scene%network%position(:, pair(1))
                length0(e) = norm2(before)
                stretch(e) = 1.0_wp
                if (length0(e) > 0.0_wp) stretch(e) = norm2(now) / length0(e)
                period(:, e) = scene%link_period(:, l) &
                    * (1.0_wp + p_disp * scene%link_strain(:, l))
            end associate
        end do
        offsets = [(2_int64 * e, e = 1, n_cells)]

        vtu%ascii = self%ascii
        vtu%xml = '<?xml version="1.0"?>' // new_line('a') &
            // '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="' &
            // get_byte_order() // '" header_type="UInt64">' // new_line('a') &
            // '<UnstructuredGrid>' // new_line('a') // '<FieldData>' // new_line('a')
        vtu%appended = ''
        call add_reals(vtu, 'time', [state%time], 1, field=.true.)
        call add_int32(vtu, 'step', [int(state%step, int32)], field=.true.)
        do l = 1, size(state%factors)
            call add_reals(vtu, trim(scene%path%channel(l)), [state%factors(l)], 1, &
                field=.true.)
        end do
        if (scene%fabric_set > 0) then
            ! A fabric has the two default channels: p_disp is channel 2.
            call add_reals(vtu, 'strain', [state%factors(2) * scene%fabric_strain], 1, &
                field=.true.)
            call add_reals(vtu, 'force_per_width', &
                [state%reaction(1, scene%fabric_set) / scene%fabric_width], 1, field=.true.)
        end if
        call add_text(vtu, '</FieldData>')
        call add_text(vtu, '<Piece NumberOfPoints="' // format_integer(n_nodes) &
            // '" NumberOfCells="' // format_integer(n_cells) // '">')
        call add_text(vtu, '<PointData Vectors="displacement">')
        call add_reals(vtu, 'displacement', &
            reshape(state%position - scene%network%position, [3 * n_nodes]), 3)
        call add_reals(vtu, 'position', reshape(state%position, [3 * n_nodes]), 3)
        if (scene%passages%size() > 0) then
            allocate(contact(n_nodes), source=int(contact_none, int32))
            do p = 1, scene%passages%size()
                node = scene%passages%node(p)
                if (contact(node) == contact_none) contact(node) = contact_stick
                if (p <= size(mode)) then
                    if (mode(p) /= 0) contact(node) = contact_slip
                end if
            end do
            call add_int32(vtu, 'contact_state', contact)
            if (size(mode) == scene%passages%size() .and. size(flow) == size(mode)) &
                call add_passage_data(vtu, scene, state, mode, flow, n_nodes)
        end if
        call add_text(vtu, '</PointData>')
        call add_text(vtu, '<CellData Scalars="tension">')
        call add_reals(vtu, 'tension', tension, 1)
        call add_reals(vtu, 'stretch', stretch, 1)
        call add_reals(vtu, 'L0', length0, 1)
        call add_reals(vtu, 'period', reshape(period, [3 * n_cells]), 3)
        call add_int32(vtu, 'kind', cell_kind)
        call add_int32(vtu, 'yarn', yarn)
        call add_int32(vtu, 'material', material)
        call add_text(vtu, '</CellData>')
        call add_text(vtu, '<Points>')
        call add_reals(vtu, 'Points', reshape(state%position, [3 * n_nodes]), 3)
        call add_text(vtu, '</Points>')
        call add_text(vtu, '<Cells>')
        call add_int64(vtu, 'connectivity', connectivity)
        call add_int64(vtu, 'offsets', offsets)
        call add_uint8(vtu, 'types', spread(vtk_line, 1, n_cells))
        call add_text(vtu, '</Cells>')
        call add_text(vtu, '</Piece>')
        call add_text(vtu, '</UnstructuredGrid>')
        if (.not. vtu%ascii) then
            call add_text(vtu, '<AppendedData encoding="base64">')
            vtu%xml = vtu%xml // '_' // vtu%appended // new_line('a')
            call add_text(vtu, '</AppendedData>')
        end if
        call add_text(vtu, '</VTKFile>')
        call write_text_file(path, vtu%xml, error)
        if (allocated(error)) return

        call add_file(self, name, state%time)
        if (self%n_files <= collection_always .or. &
                real(self%n_files - self%listed, wp) > collection_lag * self%n_files) &
            call self%write_collection(error)
    end subroutine write_state

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

    !> Write states.pvd.tmp and rename it over states.pvd. The text is built in one
    !> buffer sized for every entry, so a rewrite costs time linear in its entries.
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
            call put(trim(self%files(i)))
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

    !> Write `text` to `path` (a stream, so lines of any length), checking every write
    !> and the close; with `atomic`, through path.tmp renamed over path. On failure the
    !> incomplete file is removed.
    subroutine write_text_file(path, text, error, atomic)
        character(len=*), intent(in) :: path, text
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: atomic
        type(error_type), allocatable :: ignored
        character(len=:), allocatable :: target
        character(len=256) :: message
        integer :: unit, status
        logical :: through_temporary

        through_temporary = .false.
        if (present(atomic)) through_temporary = atomic
        target = path
        if (through_temporary) target = path // '.tmp'
        call open_new_file(unit, target, error, stream=.true.)
        if (allocated(error)) then
            call remove_file(target, ignored)
            return
        end if
        message = ''
        write(unit, iostat=status, iomsg=message) text
        call close_new_file(unit, target, error, status, message)
        if (allocated(error) .or. .not. through_temporary) return
        call rename_file(target, path, error)
        if (allocated(error)) call remove_file(target, ignored)
    end subroutine write_text_file

    subroutine add_text(vtu, text)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: text
        vtu%xml = vtu%xml // text // new_line('a')
    end subroutine add_text

    !> The DataArray element of an array: `values` inline as ASCII, or an offset into the
    !> appended data (where the byte count and `bytes`, their binary form, go, each
    !> base64-encoded).
    subroutine add_array(vtu, type_name, label, components, n_tuples, field, bytes, values)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: type_name, label
        integer, intent(in) :: components, n_tuples
        logical, intent(in) :: field
        integer(int8), intent(in) :: bytes(:)
        class(*), intent(in) :: values(:)
        character(len=:), allocatable :: attributes

        attributes = '<DataArray type="' // type_name // '" Name="' // label // '"'
        if (components > 1) attributes = attributes // ' NumberOfComponents="' &
            // format_integer(components) // '"'
        if (field) attributes = attributes // ' NumberOfTuples="' &
            // format_integer(n_tuples) // '"'
        if (vtu%ascii) then
            call add_text(vtu, attributes // ' format="ascii">' // format_values(values) &
                // '</DataArray>')
        else
            call add_text(vtu, attributes // ' format="appended" offset="' &
                // format_integer(len(vtu%appended)) // '"/>')
            vtu%appended = vtu%appended &
                // encode_base64(transfer(int(size(bytes), int64), [0_int8])) &
                // encode_base64(bytes)
        end if
    end subroutine add_array

    !> Point data of the passages: count, the shown passage (rule in write_state), its
    !> mode code and values.
    subroutine add_passage_data(vtu, scene, state, mode, flow, n_nodes)
        type(vtu_builder_type), intent(inout) :: vtu
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: mode(:), n_nodes
        real(wp), intent(in) :: flow(:)
        !> Rank of each mode code for the choice of the shown passage (higher wins).
        integer, parameter :: rank(0:4) = [0, 1, 3, 3, 2]
        type(passage_state_type) :: ps
        integer(int32), allocatable :: count(:), shown(:), code(:)
        real(wp), allocatable :: values(:, :)
        integer :: p, node, q

        call get_passage_states(scene, state, mode, flow, ps)
        allocate(count(n_nodes), shown(n_nodes), code(n_nodes), source=0_int32)
        allocate(values(n_nodes, 5), source=0.0_wp)
        do p = 1, scene%passages%size()
            node = scene%passages%node(p)
            count(node) = count(node) + 1
            q = shown(node)
            if (q > 0) then
                if (rank(ps%mode(p)) < rank(ps%mode(q))) cycle
                if (rank(ps%mode(p)) == rank(ps%mode(q)) .and. &
                    .not. ps%tension_max(p) > ps%tension_max(q)) cycle
            end if
            shown(node) = int(p, int32)
            code(node) = int(ps%mode(p), int32)
            values(node, :) = [ps%flow(p), ps%tension_min(p), ps%tension_max(p), &
                ps%critical(p), ps%angle(p)]
        end do
        call add_int32(vtu, 'passages', count)
        call add_int32(vtu, 'passage', shown)
        call add_int32(vtu, 'mode', code)
        call add_reals(vtu, 'flow', values(:, 1), 1)
        call add_reals(vtu, 'tension_min', values(:, 2), 1)
        call add_reals(vtu, 'tension_max', values(:, 3), 1)
        call add_reals(vtu, 'critical_tension', values(:, 4), 1)
        call add_reals(vtu, 'wrap_angle', values(:, 5), 1)
    end subroutine add_passage_data

    subroutine add_reals(vtu, label, values, components, field)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        real(wp), intent(in) :: values(:)
        integer, intent(in) :: components
        logical, intent(in), optional :: field

        call add_array(vtu, 'Float64', label, components, size(values) / components, &
            is_field(field), transfer(values, [0_int8], 8 * size(values)), values)
    end subroutine add_reals

    subroutine add_int32(vtu, label, values, field)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        integer(int32), intent(in) :: values(:)
        logical, intent(in), optional :: field

        call add_integers(vtu, 'Int32', label, int(values, int64), &
            transfer(values, [0_int8], 4 * size(values)), field)
    end subroutine add_int32

    subroutine add_int64(vtu, label, values)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        integer(int64), intent(in) :: values(:)

        call add_integers(vtu, 'Int64', label, values, transfer(values, [0_int8], 8 * size(values)))
    end subroutine add_int64

    subroutine add_uint8(vtu, label, values)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        integer(int8), intent(in) :: values(:)

        call add_integers(vtu, 'UInt8', label, int(values, int64), values)
    end subroutine add_uint8

    !> An integer array of VTK type `type_name`: `values` in ASCII, or `bytes`, their
    !> binary form in that type, appended.
    subroutine add_integers(vtu, type_name, label, values, bytes, field)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: type_name, label
        integer(int64), intent(in) :: values(:)
        integer(int8), intent(in) :: bytes(:)
        logical, intent(in), optional :: field

        call add_array(vtu, type_name, label, 1, size(values), is_field(field), bytes, values)
    end subroutine add_integers

    !> The ASCII form of a DataArray: ' v1 v2 ...', reals as es24.16e3, integers as i0.
    function format_values(values) result(text)
        class(*), intent(in) :: values(:)
        character(len=:), allocatable :: text
        integer :: status

        select type (values)
        type is (real(wp))
            allocate(character(len=25 * size(values) + 1) :: text)
            write(text, '(*(1x, es24.16e3))', iostat=status) values
        type is (integer(int64))
            allocate(character(len=21 * size(values) + 1) :: text)
            write(text, '(*(1x, i0))', iostat=status) values
        end select
        text = trim(text)
    end function format_values

    pure logical function is_field(field)
        logical, intent(in), optional :: field
        is_field = .false.
        if (present(field)) is_field = field
    end function is_field

    !> Base64 (RFC 4648, with '=' padding) of `bytes`.
    pure function encode_base64(bytes) result(text)
        integer(int8), intent(in) :: bytes(:)
        character(len=:), allocatable :: text
        integer :: i, j, n, b1, b2, b3, group

        n = size(bytes)
        allocate(character(len=4 * ((n + 2) / 3)) :: text)
        j = 0
        do i = 1, n, 3
            b1 = iand(int(bytes(i)), 255)
            b2 = 0
            b3 = 0
            if (i + 1 <= n) b2 = iand(int(bytes(i + 1)), 255)
            if (i + 2 <= n) b3 = iand(int(bytes(i + 2)), 255)
            group = ior(ior(ishft(b1, 16), ishft(b2, 8)), b3)
            text(j + 1:j + 1) = base64_alphabet(ishft(group, -18) + 1:ishft(group, -18) + 1)
            text(j + 2:j + 2) = base64_alphabet(iand(ishft(group, -12), 63) + 1: &
                iand(ishft(group, -12), 63) + 1)
            text(j + 3:j + 3) = base64_alphabet(iand(ishft(group, -6), 63) + 1: &
                iand(ishft(group, -6), 63) + 1)
            text(j + 4:j + 4) = base64_alphabet(iand(group, 63) + 1:iand(group, 63) + 1)
            if (i + 1 > n) text(j + 3:j + 3) = '='
            if (i + 2 > n) text(j + 4:j + 4) = '='
            j = j + 4
        end do
    end function encode_base64

    !> 'LittleEndian' or 'BigEndian': the byte order of this machine.
    pure function get_byte_order() result(order)
        character(len=:), allocatable :: order
        integer(int8) :: bytes(4)
        bytes = transfer(1_int32, bytes)
        if (bytes(1) == 1_int8) then
            order = 'LittleEndian'
        else
            order = 'BigEndian'
        end if
    end function get_byte_order

end module yarnfort_output_vtk
