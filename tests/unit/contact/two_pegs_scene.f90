! SPDX-License-Identifier: MIT
!> The small contact scene of the contact and row-update unit tests.
module two_pegs_scene
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_scene_builder, only: new_scene
    implicit none
    private

    public :: make_scene

contains

    !> A yarn A-C-E-B (two elements per segment) passing two contact nodes C and E, each
    !> also the end of a peg yarn anchored at D1, D2. A, B, D1, D2 are fixed; A and B are
    !> pulled along x: a rigid translation, so without `prestress` (of the yarn and the
    !> pegs, N) every solution of the scene is unstressed.
    subroutine make_scene(scene, error, prestress)
        type(scene_type), intent(out) :: scene
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: prestress(2)
        type(config_type) :: config

        config%node_positions = reshape([-1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, -0.3_wp, 0.1_wp, &
            0.8_wp, -0.2_wp, -0.1_wp, 1.5_wp, 0.2_wp, 0.0_wp, 0.0_wp, -1.0_wp, 0.0_wp, &
            0.8_wp, -1.0_wp, 0.3_wp], [3, 6])
        allocate(config%materials(2))
        config%materials(1)%name = 'yarn'
        config%materials(1)%law = 'neo_hookean'
        config%materials(1)%modulus = 1.0e6_wp
        config%materials(1)%area = 1.0e-5_wp
        config%materials(2)%name = 'peg'
        config%materials(2)%law = 'linear'
        config%materials(2)%stiffness = 20.0_wp
        if (present(prestress)) config%materials(:)%prestress = prestress
        allocate(config%yarns(3))
        config%yarns(1)%material = 'yarn'
        config%yarns(1)%nodes = [1, 2, 3, 4]
        config%yarns(1)%elements_per_segment = 2
        config%yarns(2)%material = 'peg'
        config%yarns(2)%nodes = [2, 5]
        config%yarns(3)%material = 'peg'
        config%yarns(3)%nodes = [3, 6]
        allocate(config%supports(1))
        config%supports(1)%name = 'fixed'
        config%supports(1)%nodes = [1, 4, 5, 6]
        config%supports(1)%displacement = [0.1_wp, 0.0_wp, 0.0_wp]
        allocate(config%loads(0))
        allocate(config%contacts(1))
        config%contacts(1)%materials = [character(len=64) :: 'yarn', 'peg']
        config%contacts(1)%law = 'adhesion'
        config%contacts(1)%friction_coefficient = 0.3_wp
        config%contacts(1)%adhesion = 0.05_wp
        config%path%time = [0.0_wp, 1.0_wp]
        config%path%p_force = [0.0_wp, 0.0_wp]
        config%path%p_disp = [0.0_wp, 1.0_wp]
        call new_scene(scene, config, error)
    end subroutine make_scene

end module two_pegs_scene
