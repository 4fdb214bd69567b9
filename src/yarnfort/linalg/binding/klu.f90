! SPDX-License-Identifier: MIT
!> bind(C) interfaces to KLU's 64-bit API (`klu_l_*`, SuiteSparse_long = C long) and a
!> Fortran mirror of `klu_l_common`. The struct is plain data (doubles, longs, two
!> pointers, two size_t), unchanged from KLU 1.0 through KLU 2.x, so it is mirrored here
!> instead of going through a C shim. Only yarnfort_linalg_backend_klu uses this module.
module yarnfort_linalg_binding_klu
    use, intrinsic :: iso_c_binding, only: c_long, c_double, c_size_t, c_ptr, c_funptr
    implicit none
    private

    public :: klu_l_common, klu_l_numeric_sizes, klu_l_symbolic
    public :: klu_ok, klu_singular, klu_out_of_memory, klu_invalid, klu_too_large
    public :: klu_l_defaults, klu_l_analyze, klu_l_analyze_given, klu_l_factor
    public :: klu_l_refactor, klu_l_solve
    public :: klu_l_rcond, klu_l_free_symbolic, klu_l_free_numeric

    !> Status codes stored in klu_l_common%status (klu.h).
    integer(c_long), parameter :: klu_ok = 0, klu_singular = 1, klu_out_of_memory = -2, &
        klu_invalid = -3, klu_too_large = -4

    !> Mirror of `klu_l_common` (klu.h): parameters, then statistics.
    type, bind(C) :: klu_l_common
        real(c_double) :: tol, memgrow, initmem_amd, initmem, maxwork
        integer(c_long) :: btf, ordering, scale
        type(c_funptr) :: user_order
        type(c_ptr) :: user_data
        integer(c_long) :: halt_if_singular
        integer(c_long) :: status, nrealloc, structural_rank, numerical_rank, singular_col, &
            noffdiag
        real(c_double) :: flops, rcond, condest, rgrowth, work
        integer(c_size_t) :: memusage, mempeak
    end type klu_l_common

    !> The leading members of `klu_l_numeric` (klu.h): order, blocks, and the actual
    !> numbers of entries in L and U (diagonals included).
    type, bind(C) :: klu_l_numeric_sizes
        integer(c_long) :: n, nblocks, lnz, unz
    end type klu_l_numeric_sizes

    !> Mirror of `klu_l_symbolic` (klu.h). AMD's predictions for the ordering it found
    !> (filled for AMD only), summed over the diagonal blocks of the block triangular
    !> form: symmetry of the largest block, flop count of the factorisation and nonzeros
    !> of L and U (diagonals included), pivoting on the diagonal. Then the order, the
    !> row and column permutations P and Q (0-based, size n: A(P, Q) is block upper
    !> triangular with its blocks ordered) and the block boundaries R.
    type, bind(C) :: klu_l_symbolic
        real(c_double) :: symmetry, est_flops, lnz, unz
        type(c_ptr) :: lnz_per_block
        integer(c_long) :: n, nz
        type(c_ptr) :: p, q, r
        integer(c_long) :: nzoff, nblocks, maxblock, ordering, do_btf, structural_rank
    end type klu_l_symbolic

    interface
        !> Set default parameters; returns TRUE (1) on success.
        function klu_l_defaults(common) result(ok) bind(C, name='klu_l_defaults')
            import :: c_long, klu_l_common
            type(klu_l_common), intent(inout) :: common
            integer(c_long) :: ok
        end function klu_l_defaults

        !> BTF + AMD ordering of the pattern; returns the Symbolic object or NULL.
        function klu_l_analyze(n, ap, ai, common) result(symbolic) &
                bind(C, name='klu_l_analyze')
            import :: c_long, c_ptr, klu_l_common
            integer(c_long), value :: n
            integer(c_long), intent(in) :: ap(*), ai(*)
            type(klu_l_common), intent(inout) :: common
            type(c_ptr) :: symbolic
        end function klu_l_analyze

        !> BTF with the given row and column orders P and Q (0-based) instead of AMD's;
        !> returns the Symbolic object (without AMD's estimates) or NULL.
        function klu_l_analyze_given(n, ap, ai, p, q, common) result(symbolic) &
                bind(C, name='klu_l_analyze_given')
            import :: c_long, c_ptr, klu_l_common
            integer(c_long), value :: n
            integer(c_long), intent(in) :: ap(*), ai(*), p(*), q(*)
            type(klu_l_common), intent(inout) :: common
            type(c_ptr) :: symbolic
        end function klu_l_analyze_given

        !> Factorisation with partial pivoting; returns the Numeric object or NULL.
        function klu_l_factor(ap, ai, ax, symbolic, common) result(numeric) &
                bind(C, name='klu_l_factor')
            import :: c_long, c_double, c_ptr, klu_l_common
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), value :: symbolic
            type(klu_l_common), intent(inout) :: common
            type(c_ptr) :: numeric
        end function klu_l_factor

        !> New values, same pivot order as the existing Numeric object; returns TRUE/FALSE.
        function klu_l_refactor(ap, ai, ax, symbolic, numeric, common) result(ok) &
                bind(C, name='klu_l_refactor')
            import :: c_long, c_double, c_ptr, klu_l_common
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), value :: symbolic, numeric
            type(klu_l_common), intent(inout) :: common
            integer(c_long) :: ok
        end function klu_l_refactor

        !> In-place solve of A X = B, B of leading dimension ldim with nrhs columns.
        function klu_l_solve(symbolic, numeric, ldim, nrhs, b, common) result(ok) &
                bind(C, name='klu_l_solve')
            import :: c_long, c_double, c_ptr, klu_l_common
            type(c_ptr), value :: symbolic, numeric
            integer(c_long), value :: ldim, nrhs
            real(c_double), intent(inout) :: b(*)
            type(klu_l_common), intent(inout) :: common
            integer(c_long) :: ok
        end function klu_l_solve

        !> Cheap reciprocal condition estimate min|U(k,k)|/max|U(k,k)| into common%rcond.
        function klu_l_rcond(symbolic, numeric, common) result(ok) bind(C, name='klu_l_rcond')
            import :: c_long, c_ptr, klu_l_common
            type(c_ptr), value :: symbolic, numeric
            type(klu_l_common), intent(inout) :: common
            integer(c_long) :: ok
        end function klu_l_rcond
    end interface

    abstract interface
        !> klu_l_free_symbolic and klu_l_free_numeric: free a Symbolic or Numeric object and
        !> nullify the pointer; return TRUE/FALSE.
        function klu_l_free_interface(object, common) result(ok) bind(C)
            import :: c_long, c_ptr, klu_l_common
            type(c_ptr), intent(inout) :: object
            type(klu_l_common), intent(inout) :: common
            integer(c_long) :: ok
        end function klu_l_free_interface
    end interface

    !> Free and nullify the Symbolic object.
    procedure(klu_l_free_interface), bind(C, name='klu_l_free_symbolic') :: &
        klu_l_free_symbolic
    !> Free and nullify the Numeric object.
    procedure(klu_l_free_interface), bind(C, name='klu_l_free_numeric') :: klu_l_free_numeric

end module yarnfort_linalg_binding_klu
