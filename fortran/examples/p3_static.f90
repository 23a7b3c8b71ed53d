!> P3 (two bars, static contact) through the Fortran module `martello` (fortran/martello.f90),
!> checked against the closed form of docs/problems.md P3 coded here independently, for Lagrange,
!> penalty and augmented Lagrange, and with every segment refined into 1, 2, 8 and 64
!> elements (linear FE is nodally exact for point loads, so the coarse nodes must not move).
!> Stops with a non-zero code on failure.
program p3_static
   use martello
   implicit none
   real(dp), parameter :: r = 2.1e7_dp, d = 1.0e-3_dp, f = 5.0e4_dp, eps = 100.0_dp*r
   integer :: ne, refinements(4) = [1, 2, 8, 64], i, failures = 0, checks = 0
   real(dp) :: want(4)

   ! Lagrange closed form: u1 = (2F/r + d)/3, u2 = (F/r + 2d)/3, u3 = (F/r − d)/3, P = (F − rd)/3.
   want = [(2*f/r + d)/3, (f/r + 2*d)/3, (f/r - d)/3, (f - r*d)/3]
   do i = 1, size(refinements)
      ne = refinements(i)
      ! dense KKT solves of size ≤ 3·64+2, condition ≲ 1e5: 1e-12 leaves 3 digits of margin
      call run(SCHEME_LAGRANGE, ne, want, 1.0e-12_dp, 'lagrange')
      call run(SCHEME_AUGMENTED, ne, want, 1.0e-12_dp, 'augmented')
   end do
   ! Penalty closed form: P = ε(F/r − d)/(1 + 3ε/r); nodes from equilibrium with that P.
   block
      real(dp) :: p
      p = eps*(f/r - d)/(1.0_dp + 3.0_dp*eps/r)
      ! Equilibrium of the three free nodes by hand: u3 = P/r (right bar carries P),
      ! u2 = u1 − P/r (element 1–2 carries P), r u1 + P = F → u1 = (F − P)/r.
      want = [(f - p)/r, (f - p)/r - p/r, p/r, p]
      do i = 1, size(refinements)
         ! P = εδ with δ/d ≈ 1e-2: two digits cancel, so 1e-10
         call run(SCHEME_PENALTY, refinements(i), want, 1.0e-10_dp, 'penalty')
      end do
   end block

   print '(a,i0,a,i0,a)', 'p3_static: ', checks - failures, ' passed, ', failures, ' failed'
   if (failures > 0) error stop 1

contains

   subroutine run(scheme, ne, expected, rtol, label)
      integer, intent(in) :: scheme, ne
      real(dp), intent(in) :: expected(4), rtol
      character(len=*), intent(in) :: label
      type(model_t) :: m
      type(static_result_t) :: res
      real(dp) :: lpar(NPAR_LINK), cpar(NPAR_CONTACT), tpar(NPAR_TF), empty(0), got(4)
      integer :: n, stat, j, n1, n2, n3
      ! nodes: left support, 2·ne elements to n2 (n1 at ne), then n3 and ne elements to support
      n = 2*ne + 1 + ne + 1
      call model_init(m, n, 3*ne, 1, 1, 0, stat)
      do j = 1, n
         call model_set_node(m, j, 1.0_dp, 0.0_dp, 0.0_dp, j == 1 .or. j == n, stat)
      end do
      lpar = 0.0_dp; lpar(L_STIFF) = r*ne    ! EA/(l/ne)
      do j = 1, 2*ne
         call model_add_link(m, LINK_BAR, j, j + 1, lpar, stat)
      end do
      do j = 2*ne + 2, n - 1
         call model_add_link(m, LINK_BAR, j, j + 1, lpar, stat)
      end do
      n1 = ne + 1; n2 = 2*ne + 1; n3 = 2*ne + 2
      cpar = 0.0_dp; cpar(P_STIFF) = eps
      call model_add_contact(m, n2, n3, d, scheme, LAW_LINEAR, cpar, stat)
      tpar = 0.0_dp; tpar(1) = f
      call model_add_nodal_force(m, n1, TF_CONSTANT, tpar, empty, empty, stat)
      call static_solve(m, 1.0e-14_dp, 500, res, stat)
      got = [res%u(n1), res%u(n2), res%u(n3), res%force(1)]
      do j = 1, 4
         checks = checks + 1
         if (stat /= MARTELLO_OK .or. abs(got(j) - expected(j)) > rtol*abs(expected(j))) then
            failures = failures + 1
            print '(a,a,i0,a,i0,2(a,es25.16e3),a,i0)', 'FAIL ', label//' ne=', ne, ' value ', j, &
               ': got ', got(j), ' want ', expected(j), ' status ', stat
         end if
      end do
   end subroutine run
end program p3_static
