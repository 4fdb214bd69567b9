! SPDX-License-Identifier: MIT
!> What the user asked for, as read from the namelist input, before any scene is built.
!> Plain data with defaults; units are SI (N, m) unless a unit is given. The types of the
!> namelist groups come from their description (variables.py, generated into
!> yarnfort_input_groups); reading is in yarnfort_input_namelist; building the scene from
!> it is in yarnfort_scene.
module yarnfort_input_config
    use yarnfort_kinds, only: wp
    use yarnfort_input_groups, only: control_config_type, solver_config_type, &
        material_config_type, contact_config_type, fabric_config_type, geometry_config_type, &
        yarn_config_type, support_config_type, load_config_type, path_config_type, &
        output_config_type, obstacle_config_type, ring_config_type, name_length, path_length
    implicit none
    private

    public :: config_type, control_config_type, solver_config_type, material_config_type
    public :: yarn_config_type, support_config_type, load_config_type, path_config_type
    public :: output_config_type, geometry_config_type, name_length, path_length
    public :: contact_config_type, fabric_config_type, link_config_type
    public :: obstacle_config_type, ring_config_type

    !> A node that follows another one: a periodic image (eq. 53) or the other side of
    !> a gap-holder. Made by the fabric generators.
    type :: link_config_type
        integer :: follower = 0
        integer :: leader = 0
        !> follower = leader + offset + p_disp * strain * offset (componentwise), with
        !> offset the initial difference of their positions; a gap link scales the
        !> offset by the gap factor instead.
        real(wp) :: strain(3) = 0.0_wp
        logical :: gap = .false.
        !> Gap link only: the part of the offset that is a lattice vector (a gap-holder
        !> to a periodic image, TexGen import); it follows the macroscopic strain
        !> (p_disp * strain * period), the rest is the gap.
        real(wp) :: period(3) = 0.0_wp
        !> Gap link only: the two nodes are sewn together, not one contact (no passage
        !> at either for the other's yarn; the clamped knit's edge threads).
        logical :: bonded = .false.
    end type link_config_type

    !> The whole input.
    type :: config_type
        type(control_config_type) :: control
        type(solver_config_type) :: solver
        type(material_config_type), allocatable :: materials(:)
        !> &geometry group: a file with the nodes and yarns (then no &nodes or &yarn).
        type(geometry_config_type) :: geometry
        !> &nodes group or geometry file: node coordinates (3, n_nodes), ids 1..n_nodes.
        real(wp), allocatable :: node_positions(:, :)
        !> &yarn groups or geometry file.
        type(yarn_config_type), allocatable :: yarns(:)
        type(support_config_type), allocatable :: supports(:)
        type(load_config_type), allocatable :: loads(:)
        type(contact_config_type), allocatable :: contacts(:)
        !> Contact nodes of one or more yarns: fixed obstacles and free rings.
        type(obstacle_config_type), allocatable :: obstacles(:)
        type(ring_config_type), allocatable :: rings(:)
        !> &fabric group (kind = '': none) and the links its generator made.
        type(fabric_config_type) :: fabric
        type(link_config_type), allocatable :: links(:)
        !> Generated fabrics: width (m) across which the x force is carried, and the
        !> support whose x reaction is the fabric's force (0: not a fabric).
        real(wp) :: fabric_width = 0.0_wp
        integer :: fabric_support = 0
        !> TexGen import (&fabric kind = 'texgen'): yarns and contacts found.
        integer :: texgen_yarns = 0
        integer :: texgen_contacts = 0
        type(path_config_type) :: path
        type(output_config_type) :: output
        !> Not a namelist variable: the folder of the input file, against which relative
        !> file names in the input are resolved ('' = the working directory, as for stdin).
        character(len=path_length) :: input_folder = ''
    end type config_type

end module yarnfort_input_config
