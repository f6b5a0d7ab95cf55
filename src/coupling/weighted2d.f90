!> alpha-weighted mass and stiffness of a 2D continuum in an Arlequin overlap (doc/continuum.md,
!> "Arlequin coupling in 2D"; doc/theory.md section 6.9):
!>   K_alpha = int alpha B^T D B t dA,   M_alpha = int alpha rho t N^T N dA,
!> with alpha = the FE weight of a coupling_overlap2d weight field (one region or a set of
!> disjoint regions; 1 outside). Elements whose bounding
!> box misses the region's are assembled with their own rule (alpha = 1, bitwise the
!> unweighted model); the others by the element's rule of n Gauss-Legendre points per direction
!> (`element2d_t%gauss_rule`: n x n Gauss on Q4, its collapsed (Duffy) form on T3), n = `order`
!> (default 4). A polynomial alpha of degree d
!> on an element lying in the region is integrated exactly when 2 n - 1 >= d + 2 (Q4 mass,
!> per direction); across the region's boundary alpha has a kink and the rule is only
!> convergent (refine the mesh or raise the order there).
module coupling_weighted2d
    use core_kinds, only: wp
    use core_error, only: error_t, make_error
    use fem_continuum_model, only: continuum_model_t
    use fem_element2d, only: element2d_t
    use fem_elastic2d, only: elastic2d_t
    use fem_triplets, only: fem_triplets_t
    use fem_mass_scheme, only: mass_scheme_t, consistent_mass_t
    use coupling_overlap2d, only: weight_field_t
    implicit none
    private
    public :: assemble_weighted

contains

    !> Weighted stiffness and mass (consistent, or row-sum lumped) over all dofs, as triplets.
    subroutine assemble_weighted(model, region, k, m, error, mass, order)
        !> The continuum model (materials assigned).
        type(continuum_model_t), intent(in) :: model
        !> The overlap weight (one region, or a set of regions).
        class(weight_field_t), intent(in) :: region
        !> Weighted stiffness.
        type(fem_triplets_t), intent(out) :: k
        !> Weighted mass.
        type(fem_triplets_t), intent(out) :: m
        !> Set when an element has no material or the order is out of 1..10.
        type(error_t), allocatable, intent(out) :: error
        !> How the element masses enter: consistent (the default) or row-sum lumped.
        class(mass_scheme_t), intent(in), optional :: mass
        !> Gauss points per direction in the elements touching the region (default 4).
        integer, intent(in), optional :: order
        real(wp), allocatable :: xe(:, :), ke(:, :), me(:, :), pts(:, :), w(:)
        integer, allocatable :: dofs(:), nodes(:)
        class(mass_scheme_t), allocatable :: scheme
        integer :: e, nq
        call model%check(error)
        if (allocated(error)) return
        nq = 4
        if (present(order)) nq = order
        if (nq < 1 .or. nq > 10) then
            call make_error(error, 'weighted assembly: order must lie in 1..10 Gauss points per direction')
            return
        end if
        if (present(mass)) then
            allocate (scheme, source=mass)
        else
            allocate (consistent_mass_t :: scheme)
        end if
        call k%init(model%dof_count(), 64*model%mesh%element_count())
        call m%init(model%dof_count(), 64*model%mesh%element_count())
        do e = 1, model%mesh%element_count()
            xe = model%mesh%element_coordinates(e)
            nodes = model%mesh%element_nodes(e)
            dofs = reshape(transpose(reshape([2*nodes - 1, 2*nodes], [size(nodes), 2])), [2*size(nodes)])
            associate (el => model%family(model%mesh%kind(e))%element, mat => model%materials(model%element_material(e)))
                if (region%misses([minval(xe(1, :)), maxval(xe(1, :)), minval(xe(2, :)), maxval(xe(2, :))])) then
                    ke = el%stiffness(xe, mat)
                    me = el%mass_consistent(xe, mat)
                else
                    call el%gauss_rule(nq, pts, w)
                    call weighted_element(el, xe, mat, region, pts, w, ke, me)
                end if
            end associate
            call k%add_block(dofs, ke)
            call scheme%add_element(m, dofs, me, sum(me, dim=2))
        end do
    end subroutine assemble_weighted

    !> Element matrices with the weight at every quadrature point.
    subroutine weighted_element(el, xe, mat, region, pts, w, ke, me)
        class(element2d_t), intent(in) :: el
        real(wp), intent(in) :: xe(:, :)
        type(elastic2d_t), intent(in) :: mat
        class(weight_field_t), intent(in) :: region
        real(wp), intent(in) :: pts(:, :), w(:)
        real(wp), allocatable, intent(out) :: ke(:, :), me(:, :)
        real(wp), allocatable :: n(:), dndx(:, :), b(:, :)
        real(wp) :: detj, alpha, xq(2), d(3, 3), dw
        integer :: q, nn, a, c
        nn = size(xe, 2)
        allocate (n(nn), dndx(nn, 2), ke(2*nn, 2*nn), me(2*nn, 2*nn), source=0.0_wp)
        d = mat%d_matrix()
        do q = 1, size(w)
            call el%geometry(xe, pts(:, q), n, dndx, detj)
            xq = matmul(xe, n)
            alpha = region%alpha_fe(xq(1), xq(2))
            dw = alpha*w(q)*detj*mat%thickness
            b = el%b_matrix(xe, pts(:, q))
            ke = ke + dw*matmul(transpose(b), matmul(d, b))
            do a = 1, nn
                do c = 1, nn
                    me(2*a - 1, 2*c - 1) = me(2*a - 1, 2*c - 1) + dw*mat%density*n(a)*n(c)
                    me(2*a, 2*c) = me(2*a, 2*c) + dw*mat%density*n(a)*n(c)
                end do
            end do
        end do
    end subroutine weighted_element
end module coupling_weighted2d
