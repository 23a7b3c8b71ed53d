!> Fast nonlinear analysis (Wilson, Three-Dimensional Static and Dynamic Analysis of
!> Structures, 3rd ed. 2002, ch. 18; docs/integrators.md "fast nonlinear analysis") as a
!> stepper of the fixed-step strategy. The linear part of the scene — springs, bars,
!> dashpots, stiffness blocks, and the initial stiffness k of bilinear springs (Wilson's
!> "effective stiffness" of a nonlinear element) — is reduced to its modes (LAPACK dsygv on
!> the free DOFs: K_L φ = ω² M φ, φᵀ M φ = 1), with the modal damping c_i = φ_iᵀ C_L φ_i.
!> Everything else is a pseudo-force: penalty contacts, fluid dampers, the departure of
!> bilinear springs from k, and the off-diagonal modal damping. In modal coordinates
!>
!>     q̈_i + c_i q̇_i + ω_i² q_i = p_i,   p = Φᵀ(f_ext − f_int(u, v)) + ω²∘q + c∘q̇,
!>
!> with f_int the whole internal force (martello_assembly), so that p holds exactly the
!> external and pseudo-forces. Over a step p is taken linear in time and each modal equation
!> is advanced exactly (Nigam & Jennings 1969; here through the exponential of the augmented
!> 4 × 4 system, valid for every damping ratio, ω = 0 included); p at the end of the step
!> depends on the state there, so it is iterated to a fixed point (Wilson's iteration)
!> until ‖Δp‖∞ ≤ tol_residual·max(‖p‖∞, ‖ω²∘q‖∞, ‖c∘q̇‖∞). When that iteration contracts slowly (a stiff contact or
!> a damper whose regularised slope c·v_reg^(α−1) is large against m/h), the step switches to
!> Newton on the same fixed point, p ← p − J⁻¹(P(p) − p), J = ∂P/∂p − I from the elements'
!> tangents in modal coordinates (counted as jacobian_evaluations). With all modes (the
!> default) the linear part is exact and the only error is the linear interpolation of the
!> pseudo-forces over the step, O(h²); the modes cost a dense eigensolve, O(n³) once, and a
!> pass O(n²).
!>
!> With modal_vectors = m > 0 the basis is Wilson's load-dependent Ritz vectors (Wilson 2002,
!> ch. 14 and 18; Wilson, Yuan & Dickens 1982) instead: the start block is the initial u and v
!> and K_L⁻¹ of the spatial load patterns (M·ι of the ground motion, a unit force at each
!> loaded node) and of the nonlinear elements' force patterns (their rows gᵀ), in that order;
!> then blocks x ← K_L⁻¹ M x and, with dampers, K_L⁻¹ C_L x (the second-order Krylov space of
!> K + sC + s²M, Bai & Su 2005: a non-proportional C drives directions K_L⁻¹M alone never
!> reaches); every vector M-orthonormalised (Gram–Schmidt, twice; one that
!> vanishes is dropped) until m are kept; then the m × m eigenproblem of K_L, M on them gives
!> the Ritz modes Φ (φᵀMφ = 1, ΦᵀK_LΦ = diag ω²). K_L is factorised in band storage (shifted
!> by σM when singular: nodes held by nonlinear elements only). Setup O(n m² + n kd² m + m³),
!> a pass O(n m). Loads and pseudo-forces outside span(MΦ) are dropped: the basis must hold
!> the nonlinear patterns (m ≥ their number plus the loads' and the initial state's) for
!> Wilson's accuracy; its error against all modes is measured (docs/integrators.md).
!> m = the number of free nodes spans everything: the same run as all modes to round-off.
module martello_fast_nonlinear
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_element_rows, only: rows_t, row_lo, row_hi
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP
   use martello_assembly, only: internal_forces, external_forces, mech_commit, external_work, &
      mass_times, assemble_mass
   use martello_observer, only: observer_t, observer_work, observer_fail
   use martello_run_quantities, only: C_MODES, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS
   use martello_integrator_settings, only: integrator_settings_t
   use martello_fixed_step, only: stepper_t, stepper_start, stepper_fail, contact_state
   use martello_lapack, only: dsygv, dgesv, dgetrf, dgetrs
   use martello_links, only: LINK_FLUID_DAMPER
   use martello_model, only: SCHEME_PENALTY
   use martello_model, only: model_bandwidth
   use martello_band_matrix, only: band_t, band_init, band_zero, band_add, band_matvec, band_pin, &
      band_factor, band_solve_factored
   use martello_stability, only: free_dofs
   implicit none
   private
   public :: fast_nonlinear_t, modal_step_coefficients

   !> What to change when the dense modal arrays (nf × nf, nf free nodes) do not fit.
   character(len=*), parameter :: FIX_DENSE = 'fast-nonlinear holds dense matrices of the'// &
      ' free nodes squared: use fewer nodes, or an integrator with banded matrices (newmark, hht)'
   !> newton_setup's info when its matrices cannot be allocated
   integer, parameter :: NEWTON_NO_MEMORY = -1

   type, extends(stepper_t) :: fast_nonlinear_t
      !> nf free nodes, nm basis vectors (nf: all modes), ritz: a Ritz basis
      integer :: nf = 0, nm = 0, max_iter = 30
      logical :: ritz = .false.
      !> Ritz basis: K_L, C_L on the nodes (band), J0 unfactored, VT = ΔK Φ G1q + ΔC Φ G1v
      type(band_t) :: klb, clb
      real(dp), allocatable :: vtr(:, :), jr(:, :)
      real(dp) :: tol = 1.0e-9_dp
      integer, allocatable :: free(:)                   !< free node of each DOF
      real(dp), allocatable :: phi(:, :)                !< nf × nf, mass-normalised modes
      real(dp), allocatable :: w2(:), c(:)              !< ω², modal damping c_i = 2ζ_iω_i
      !> z_{n+1} = E z_n + G0 p_n + G1 p_{n+1} for z = (q, q̇): e11 … g1v per mode
      real(dp), allocatable :: e11(:), e12(:), e21(:), e22(:), g0q(:), g0v(:), g1q(:), g1v(:)
      real(dp), allocatable :: q(:), qd(:), qn(:), qdn(:), p(:), pn(:), ptrial(:), r(:), &
                               pbase(:), dp(:)
      real(dp), allocatable :: fint(:), fext(:), fext_n(:)
      !> the nonlinear DOFs S (s of them): Φ(S,:), K_L(S,S), C_L(S,S); J0's LU and J0⁻¹Φ(S,:)ᵀ
      integer :: ns = 0
      integer, allocatable :: sdof(:), ipiv(:), ipiv_s(:)
      real(dp), allocatable :: phis(:, :), kls(:, :), cls(:, :), j0(:, :), w(:, :), vt(:, :), &
                               small(:, :), dks(:, :), dcs(:, :), y(:), z(:)
      type(band_t) :: kband, cband
   contains
      procedure :: init
      procedure :: step
   end type fast_nonlinear_t

contains

   subroutine init(self, m, s, o, stat)
      class(fast_nonlinear_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, nf, nm, i, j, info, lwork
      integer, allocatable :: dof(:)
      real(dp), allocatable :: kl(:, :), cl(:, :), mm(:, :), work(:), x(:), y(:)
      character(len=256) :: msg

      stat = MARTELLO_OK
      n = m%n
      call stepper_start(self, m, s, o, stat)
      if (stat /= MARTELLO_OK) return
      self%advice = 'reduce dt (the pseudo-force iteration converges for small h^2 k/m)'
      self%max_iter = s%max_newton; self%tol = s%tol_residual
      call free_dofs(m, dof, nf, stat, msg)
      if (stat == MARTELLO_OK .and. s%modal_vectors > nf) then
         write (msg, '(a,i0,a,i0,a)') 'fast-nonlinear: modal_vectors = ', s%modal_vectors, &
            ' exceeds the ', nf, ' free nodes: set it to at most that (0: all modes)'
         call observer_fail(o, MARTELLO_ERR_ARGUMENT, 0.0_dp, trim(msg), stat)
         return
      end if
      self%ritz = s%modal_vectors > 0
      nm = nf
      if (stat == MARTELLO_OK) then
         self%nf = nf
         self%free = pack([(i, i = 1, n)], .not. m%fixed)
      end if
      if (stat == MARTELLO_OK .and. self%ritz) then
         ! the basis first: it has fewer vectors than asked when the Krylov space closes
         call ritz_basis(self, m, s%modal_vectors, info, msg)
         if (info /= MARTELLO_OK) then
            call observer_fail(o, info, 0.0_dp, trim(msg), stat)
            return
         end if
         nm = size(self%w2)
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
         o%counters(C_MODES) = o%counters(C_MODES) + int(nm, i8)
      end if
      if (stat == MARTELLO_OK) then
         self%nm = nm
         ! Φ (nf × nm) and every per-mode array; all modes: the dense K_L, C_L, M (nf² each)
         allocate (self%fint(0:n), self%fext(0:n), self%fext_n(0:n), x(0:n), y(0:n), &
                   self%e11(nm), self%e12(nm), self%e21(nm), self%e22(nm), self%g0q(nm), &
                   self%g0v(nm), self%g1q(nm), self%g1v(nm), self%q(nm), self%qd(nm), self%qn(nm), &
                   self%qdn(nm), self%p(nm), self%pn(nm), self%ptrial(nm), self%r(nm), &
                   self%pbase(nm), self%dp(nm), work(1), stat=stat)
         if (stat == 0 .and. .not. self%ritz) allocate (kl(nf, nf), cl(nf, nf), mm(nf, nf), &
                                                       self%phi(nf, nf), self%w2(nf), self%c(nf), stat=stat)
         if (stat /= 0) call modal_memory('the modal matrices of fast-nonlinear', &
                                          REAL_BYTES*(5*(n + 1.0_dp) + real(nf, dp)*nm + &
                                          merge(3*real(nf, dp)**2, 0.0_dp, .not. self%ritz) + 20.0_dp*nm + 1))
      end if
      if (stat == MARTELLO_OK) call band_init(self%kband, n, model_bandwidth(m), stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%cband, n, model_bandwidth(m), stat, msg)
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      if (.not. self%ritz) then
         call linear_part(m, dof, kl, cl, stat, msg)
         if (stat /= MARTELLO_OK) then
            call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
            return
         end if
         ! M on the free DOFs, column by column (lumped diagonal and consistent couplings)
         do j = 1, nf
            x = 0.0_dp
            x(self%free(j)) = 1.0_dp
            call mass_times(m, x, y)
            mm(:, j) = y(self%free)
         end do
         self%phi = kl
         call dsygv(1, 'V', 'U', nf, self%phi, nf, mm, nf, self%w2, work, -1, info)
         lwork = max(1, int(work(1))); deallocate (work)
         allocate (work(lwork), stat=stat)
         if (stat /= 0) then
            call modal_memory('the workspace of the modes (LAPACK dsygv)', REAL_BYTES*lwork)
            call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
            return
         end if
         if (nf > 0) call dsygv(1, 'V', 'U', nf, self%phi, nf, mm, nf, self%w2, work, lwork, info)
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
         o%counters(C_MODES) = o%counters(C_MODES) + int(nf, i8)
         if (info /= 0) then
            write (msg, '(a,i0,a)') 'fast-nonlinear: the modes could not be computed (LAPACK dsygv'// &
               ' info = ', info, '): the mass matrix is not positive definite on the free nodes'
            call observer_fail(o, MARTELLO_ERR_SINGULAR, 0.0_dp, trim(msg), stat)
            return
         end if
         ! K_L is positive semi-definite by construction (k > 0 elements, PSD blocks): an
         ! eigenvalue below 0 is round-off of a zero mode (a node held by nonlinear elements only)
         self%w2 = max(self%w2, 0.0_dp)
         ! modal damping: the diagonal of Φᵀ C_L Φ (the rest stays in the pseudo-force)
         do i = 1, nf
            self%c(i) = dot_product(self%phi(:, i), matmul(cl, self%phi(:, i)))
         end do
      end if
      do i = 1, self%nm
         call modal_step_coefficients(self%w2(i), self%c(i), self%h, self%e11(i), self%e12(i), &
                                      self%e21(i), self%e22(i), self%g0q(i), self%g0v(i), &
                                      self%g1q(i), self%g1v(i))
      end do
      if (self%ritz) then
         call ritz_newton_setup(self, m, dof, info, msg)
      else
         call newton_setup(self, m, dof, kl, cl, info, msg)
      end if
      if (info == NEWTON_NO_MEMORY) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      else if (info /= 0) then
         call observer_fail(o, MARTELLO_ERR_SINGULAR, 0.0_dp, 'fast-nonlinear: the constant '// &
                            'part of the Newton matrix is singular (LAPACK dgetrf)', stat)
         return
      end if
      ! modal state at t = 0: q = Φᵀ M u, q̇ = Φᵀ M v (free DOFs)
      call mass_times(m, self%u, y)
      self%q = matmul(transpose(self%phi), y(self%free))
      call mass_times(m, self%v, y)
      self%qd = matmul(transpose(self%phi), y(self%free))
      call internal_forces(m, self%ms, self%u, self%v, self%fint)
      call external_forces(m, self%mrow, 0.0_dp, self%fext)
      o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
      call modal_load(self%p)
      call set_acceleration(self)
      call mech_commit(m, self%ms, self%u)
      call contact_state(self, m)

   contains
      !> msg: the out-of-memory line of the dense modal arrays, for nf free nodes
      subroutine modal_memory(what, bytes)
         character(len=*), intent(in) :: what
         real(dp), intent(in) :: bytes
         write (msg, '(a,i0,a)') ' for ', nf, ' free nodes'
         call out_of_memory(what//trim(msg), bytes, FIX_DENSE, stat, msg)
      end subroutine modal_memory

      subroutine modal_load(pp)
         real(dp), intent(out) :: pp(:)
         real(dp) :: r(size(self%free))
         ! step by step: as one expression gfortran warned of an uninitialised temporary's
         ! descriptor (the same operations in the same order)
         r = self%fext(self%free) - self%fint(self%free)
         pp = matmul(transpose(self%phi), r)
         pp = pp + self%w2*self%q + self%c*self%qd
      end subroutine modal_load
   end subroutine init

   !> The Newton matrix's constant part and the nonlinear DOFs (docs/integrators.md): S = the
   !> free DOFs of penalty contacts, fluid dampers and bilinear springs; J0 = −I − Coff·G1v
   !> with Coff = Φᵀ C_L Φ less its diagonal; W = J0⁻¹ Φ(S,:)ᵀ.
   subroutine newton_setup(self, m, dof, kl, cl, info, msg)
      class(fast_nonlinear_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(in) :: dof(0:)
      real(dp), intent(in) :: kl(:, :), cl(:, :)
      integer, intent(out) :: info        !< NEWTON_NO_MEMORY (msg says what), or dgetrf's
      character(len=*), intent(out) :: msg
      integer :: j, nf
      character(len=96) :: what
      real(dp), allocatable :: coff(:, :)
      nf = self%nf
      self%sdof = nonlinear_dofs(m, dof, nf)
      self%ns = size(self%sdof)
      associate (s => self%sdof, ns => self%ns)
         self%phis = self%phi(s, :)
         self%kls = kl(s, s); self%cls = cl(s, s)
         allocate (self%vt(ns, nf), self%small(ns, ns), self%dks(ns, ns), self%dcs(ns, ns), &
                   self%ipiv_s(ns), self%y(nf), self%z(ns), self%j0(nf, nf), self%ipiv(nf), stat=info)
         if (info /= 0) then
            write (what, '(a,i0,a,i0,a)') 'the Newton matrices of fast-nonlinear for ', nf, &
               ' free nodes, ', ns, ' of them nonlinear'
            call out_of_memory(trim(what), REAL_BYTES*(real(ns, dp)*nf + 3*real(ns, dp)**2 + nf + ns &
                               + real(nf, dp)**2) + INT_BYTES*(ns + nf), FIX_DENSE, info, msg)
            info = NEWTON_NO_MEMORY
            return
         end if
      end associate
      coff = matmul(transpose(self%phi), matmul(cl, self%phi))
      do j = 1, nf
         coff(j, j) = 0.0_dp
         self%j0(:, j) = -coff(:, j)*self%g1v(j)
         self%j0(j, j) = self%j0(j, j) - 1.0_dp
      end do
      info = 0
      if (nf == 0) return
      call dgetrf(nf, nf, self%j0, nf, self%ipiv, info)
      if (info /= 0) return
      self%w = transpose(self%phis)
      if (self%ns > 0) call dgetrs('N', nf, self%ns, self%j0, nf, self%ipiv, self%w, nf, info)
   end subroutine newton_setup

   !> S: the free DOFs (ascending) of penalty contacts, fluid dampers and bilinear springs, where
   !> the tangents depart from K_L, C_L.
   function nonlinear_dofs(m, dof, nf) result(sdof)
      type(model_t), intent(in) :: m
      integer, intent(in) :: dof(0:), nf
      integer, allocatable :: sdof(:)
      logical :: touched(nf)
      integer :: j
      touched = .false.
      do j = 1, m%ncontact
         if (m%con_scheme(j) /= SCHEME_PENALTY) cycle
         call mark_row(m%con, j)
      end do
      do j = 1, m%nlink
         if (m%link_kind(j) == LINK_FLUID_DAMPER .or. m%link_kind(j) == LINK_BILINEAR) then
            call mark_row(m%lnk, j)
         end if
      end do
      sdof = pack([(j, j = 1, nf)], touched)
   contains
      !> The free DOFs of a row's nodes carry a nonlinear force.
      subroutine mark_row(rows, j)
         type(rows_t), intent(in) :: rows
         integer, intent(in) :: j
         integer :: k
         do k = row_lo(rows, j), row_hi(rows, j)
            if (dof(rows%node(k)) > 0) touched(dof(rows%node(k))) = .true.
         end do
      end subroutine mark_row
   end function nonlinear_dofs

   !> K_L and C_L of the linear part on the free DOFs (dof: node → DOF, 0 for fixed/ground),
   !> dense: linear_band's entries (the same sums in the same order).
   subroutine linear_part(m, dof, kl, cl, stat, msg)
      type(model_t), intent(in) :: m
      integer, intent(in) :: dof(0:)
      real(dp), intent(out) :: kl(:, :), cl(:, :)
      integer, intent(out) :: stat
      character(len=*), intent(out) :: msg
      type(band_t) :: kb, cb
      integer :: i, j, kd
      kl = 0.0_dp; cl = 0.0_dp
      kd = model_bandwidth(m)
      call band_init(kb, m%n, kd, stat, msg)
      if (stat == MARTELLO_OK) call band_init(cb, m%n, kd, stat, msg)
      if (stat /= MARTELLO_OK) return
      call linear_band(m, kb, cb)
      do j = 1, m%n
         if (dof(j) == 0) cycle
         do i = max(1, j - kd), min(m%n, j + kd)
            if (dof(i) == 0) cycle
            kl(dof(i), dof(j)) = kb%ab(2*kd + 1 + i - j, j)
            cl(dof(i), dof(j)) = cb%ab(2*kd + 1 + i - j, j)
         end do
      end do
   end subroutine linear_part

   !> K_L and C_L of the linear part on the nodes, band storage (kb, cb zero on entry): springs,
   !> bars and the initial stiffness of bilinear springs, dashpots, stiffness blocks; no term
   !> on a fixed node.
   subroutine linear_band(m, kb, cb)
      type(model_t), intent(in) :: m
      type(band_t), intent(inout) :: kb, cb
      integer :: j, p, q
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_BILINEAR)
            call add_row(kb, j, m%link_par(L_STIFF, j))
         case (LINK_DASHPOT)
            call add_row(cb, j, m%link_par(L_DAMP, j))
         end select
      end do
      do j = 1, m%nblock
         associate (nd => m%block(j)%node)
            do q = 1, size(nd)
               do p = 1, size(nd)
                  if (movable(nd(p)) .and. movable(nd(q))) then
                     call band_add(kb, nd(p), nd(q), m%block(j)%k(p, q))
                     call band_add(cb, nd(p), nd(q), m%block(j)%c(p, q))
                  end if
               end do
            end do
         end associate
      end do
   contains
      logical function movable(i)
         integer, intent(in) :: i
         movable = i > 0
         if (movable) movable = .not. m%fixed(i)
      end function movable
      !> a += val gᵀg over link j's row on the free nodes.
      subroutine add_row(a, j, val)
         type(band_t), intent(inout) :: a
         integer, intent(in) :: j
         real(dp), intent(in) :: val
         integer :: p, q, ip, iq
         do p = row_lo(m%lnk, j), row_hi(m%lnk, j)
            ip = m%lnk%node(p)
            do q = row_lo(m%lnk, j), row_hi(m%lnk, j)
               iq = m%lnk%node(q)
               if (movable(ip) .and. movable(iq)) &
                  call band_add(a, ip, iq, val*m%lnk%coef(p)*m%lnk%coef(q))
            end do
         end do
      end subroutine add_row
   end subroutine linear_band

   !> Wilson's load-dependent Ritz vectors (the module's header): self%phi (nf × k), self%w2,
   !> self%c for k ≤ nv vectors (fewer when the Krylov space closes: it then holds the whole
   !> response), self%klb, self%clb kept for the Newton matrix. info: MARTELLO_ERR_MEMORY,
   !> MARTELLO_ERR_SINGULAR (msg says why).
   subroutine ritz_basis(self, m, nv, info, msg)
      class(fast_nonlinear_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(in) :: nv
      integer, intent(out) :: info
      character(len=*), intent(out) :: msg
      type(band_t) :: kfac
      real(dp), allocatable :: x(:), y(:), xb(:, :), mx(:, :), kx(:, :), kbar(:, :), mbar(:, :), work(:)
      integer :: n, nf, kd, i, j, q, kept, first, last, lwork
      real(dp) :: kmax, mmax, sigma
      logical :: ok, damped
      character(len=160) :: what
      n = m%n; nf = self%nf; kd = model_bandwidth(m)
      info = MARTELLO_OK; msg = ''
      call band_init(self%klb, n, kd, info, msg)
      if (info == MARTELLO_OK) call band_init(self%clb, n, kd, info, msg)
      if (info == MARTELLO_OK) call band_init(kfac, n, kd, info, msg)
      if (info /= MARTELLO_OK) return
      allocate (x(0:n), y(0:n), xb(nf, nv), mx(nf, nv), stat=info)
      if (info /= 0) then
         write (what, '(a,i0,a,i0,a)') 'the Ritz vectors of fast-nonlinear (', nv, ' of ', nf, ' free nodes)'
         call out_of_memory(trim(what), REAL_BYTES*(2*(n + 1.0_dp) + 2*real(nf, dp)*nv), FIX_DENSE, info, msg)
         return
      end if
      call linear_band(m, self%klb, self%clb)
      ! K_L in band storage; singular (a node held by nonlinear elements only): K_L + σM with
      ! σ = 1e-6 of the largest k/m (1 s⁻² without stiffness), which only moves the start block
      call factor_k(0.0_dp, ok)
      if (.not. ok) then
         kmax = maxval(abs(self%klb%ab(2*kd + 1, :)))
         mmax = maxval(m%mass)
         sigma = 1.0_dp
         if (kmax > 0.0_dp .and. mmax > 0.0_dp) sigma = 1.0e-6_dp*kmax/mmax
         call factor_k(sigma, ok)
      end if
      if (.not. ok) then
         info = MARTELLO_ERR_SINGULAR
         msg = 'fast-nonlinear: the stiffness of the linear part (shifted by a small multiple of'// &
               ' M) could not be factorised for the Ritz vectors: is the mass zero on a free node?'
         return
      end if
      ! the start block: initial u, v; K_L⁻¹ of the load patterns and the nonlinear patterns
      kept = 0
      call add(self%u)
      call add(self%v)
      x = 0.0_dp; x(self%free) = self%mrow(self%free)
      call solve_add()
      do j = 1, m%nforce
         x = 0.0_dp
         if (.not. m%fixed(m%force_node(j))) x(m%force_node(j)) = 1.0_dp
         call solve_add()
      end do
      do j = 1, m%ncontact
         if (m%con_scheme(j) /= SCHEME_PENALTY) cycle
         x = 0.0_dp
         do q = row_lo(m%con, j), row_hi(m%con, j)
            x(m%con%node(q)) = m%con%coef(q)
         end do
         call solve_add()
      end do
      do j = 1, m%nlink
         if (m%link_kind(j) /= LINK_FLUID_DAMPER .and. m%link_kind(j) /= LINK_BILINEAR) cycle
         x = 0.0_dp
         do q = row_lo(m%lnk, j), row_hi(m%lnk, j)
            x(m%lnk%node(q)) = m%lnk%coef(q)
         end do
         call solve_add()
      end do
      ! blocks x ← K_L⁻¹ M x and, with damping, K_L⁻¹ C_L x (the second-order Krylov space
      ! of K + sC + s²M: a non-proportional C drives directions K_L⁻¹M alone never reaches)
      ! until nv vectors, or the space closes
      damped = any(self%clb%ab /= 0.0_dp)
      first = 1
      do while (kept < nv)
         last = kept
         if (first > last) exit
         do j = first, last
            x = 0.0_dp; x(self%free) = mx(:, j)
            call solve_add()
            if (.not. damped) cycle
            y = 0.0_dp; y(self%free) = xb(:, j)
            call band_matvec(self%clb, y(1:n), x(1:n))
            call solve_add()
         end do
         first = last + 1
      end do
      ! Rayleigh–Ritz: K̄ y = ω² M̄ y on the kept vectors, Φ = X Y
      allocate (kx(nf, kept), kbar(kept, kept), mbar(kept, kept), self%w2(kept), self%c(kept), &
                self%phi(nf, kept), work(1), stat=info)
      if (info /= 0) then
         call out_of_memory('the Ritz eigenproblem of fast-nonlinear', &
                            REAL_BYTES*(2*real(nf, dp)*kept + 2*real(kept, dp)**2), FIX_DENSE, info, msg)
         return
      end if
      do j = 1, kept
         x = 0.0_dp; x(self%free) = xb(:, j)
         call band_matvec(self%klb, x(1:n), y(1:n))
         kx(:, j) = y(self%free)
      end do
      kbar = matmul(transpose(xb(:, 1:kept)), kx)
      mbar = matmul(transpose(xb(:, 1:kept)), mx(:, 1:kept))
      if (kept > 0) then
         call dsygv(1, 'V', 'U', kept, kbar, kept, mbar, kept, self%w2, work, -1, info)
         lwork = max(1, int(work(1))); deallocate (work); allocate (work(lwork))
         call dsygv(1, 'V', 'U', kept, kbar, kept, mbar, kept, self%w2, work, lwork, info)
         if (info /= 0) then
            write (msg, '(a,i0,a)') 'fast-nonlinear: the Ritz eigenproblem failed (LAPACK dsygv info = ', &
               info, ')'
            info = MARTELLO_ERR_SINGULAR
            return
         end if
      end if
      self%phi = matmul(xb(:, 1:kept), kbar)
      self%w2 = max(self%w2, 0.0_dp)
      do i = 1, kept
         x = 0.0_dp; x(self%free) = self%phi(:, i)
         call band_matvec(self%clb, x(1:n), y(1:n))
         self%c(i) = dot_product(self%phi(:, i), y(self%free))
      end do
      info = MARTELLO_OK
   contains
      subroutine factor_k(shift, good)
         real(dp), intent(in) :: shift
         logical, intent(out) :: good
         kfac%ab = self%klb%ab
         if (shift > 0.0_dp) call assemble_mass(m, shift, kfac)
         do i = 1, n
            if (m%fixed(i)) call band_pin(kfac, i)
         end do
         call band_factor(kfac, good)
      end subroutine factor_k

      !> x ← K⁻¹ x (free part; zero on the fixed nodes), then add it
      subroutine solve_add()
         if (kept >= nv) return
         x(0) = 0.0_dp
         do i = 1, n
            if (m%fixed(i)) x(i) = 0.0_dp
         end do
         call band_solve_factored(kfac, x(1:n))
         call add(x)
      end subroutine solve_add

      !> v's free part M-orthonormalised against the kept vectors (twice), kept unless it
      !> vanishes (below 1e-8 of its M-norm: in their span)
      subroutine add(v)
         real(dp), intent(in) :: v(0:)
         real(dp) :: vf(nf), mv(nf), nrm0, nrm
         integer :: pass
         if (kept >= nv) return
         vf = v(self%free)
         call m_times(vf, mv)
         nrm0 = sqrt(max(dot_product(vf, mv), 0.0_dp))
         if (.not. (nrm0 > 0.0_dp)) return
         do pass = 1, 2
            if (kept > 0) vf = vf - matmul(xb(:, 1:kept), matmul(vf, mx(:, 1:kept)))
         end do
         call m_times(vf, mv)
         nrm = sqrt(max(dot_product(vf, mv), 0.0_dp))
         if (nrm <= 1.0e-8_dp*nrm0) return
         kept = kept + 1
         xb(:, kept) = vf/nrm
         mx(:, kept) = mv/nrm
      end subroutine add

      subroutine m_times(vf, mv)
         real(dp), intent(in) :: vf(:)
         real(dp), intent(out) :: mv(:)
         real(dp) :: xs(0:n), ys(0:n)
         xs = 0.0_dp; xs(self%free) = vf
         call mass_times(m, xs, ys)
         mv = ys(self%free)
      end subroutine m_times
   end subroutine ritz_basis

   !> The Newton matrix of a Ritz basis, J = J0 − Φᵀ(ΔK Φ G1q + ΔC Φ G1v) assembled at each
   !> update (m × m; ΔK, ΔC on the band): here J0 = −I − Coff·G1v, Coff = Φᵀ C_L Φ less its
   !> diagonal, and the work arrays.
   subroutine ritz_newton_setup(self, m, dof, info, msg)
      class(fast_nonlinear_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      integer, intent(in) :: dof(0:)
      integer, intent(out) :: info
      character(len=*), intent(out) :: msg
      real(dp), allocatable :: cphi(:, :), x(:), y(:)
      integer :: j, n, nm, nf
      n = self%klb%n; nm = self%nm; nf = self%nf
      msg = ''
      self%sdof = nonlinear_dofs(m, dof, nf)
      self%ns = size(self%sdof)
      allocate (cphi(nf, nm), self%jr(nm, nm), self%vtr(self%ns, nm), self%ipiv(nm), self%y(nm), &
                self%phis(self%ns, nm), x(0:n), y(0:n), stat=info)
      if (info /= 0) then
         call out_of_memory('the Newton matrices of fast-nonlinear', &
                            REAL_BYTES*(2*real(nf, dp)*nm + real(nm, dp)**2), FIX_DENSE, info, msg)
         info = NEWTON_NO_MEMORY
         return
      end if
      do j = 1, nm
         x = 0.0_dp; x(self%free) = self%phi(:, j)
         call band_matvec(self%clb, x(1:n), y(1:n))
         cphi(:, j) = y(self%free)
      end do
      self%phis = self%phi(self%sdof, :)
      self%jr = matmul(transpose(self%phi), cphi)
      do j = 1, nm
         self%jr(j, j) = 0.0_dp
         self%jr(:, j) = -self%jr(:, j)*self%g1v(j)
         self%jr(j, j) = self%jr(j, j) - 1.0_dp
      end do
      info = 0
   end subroutine ritz_newton_setup

   !> y = −J⁻¹ r for a Ritz basis (ritz_newton_setup), the tangents in self%kband, self%cband:
   !> ΔK, ΔC are nonzero on S only, so Vᵀ = ΔK_SS Φ_S G1q + ΔC_SS Φ_S G1v takes the pairs of S
   !> within the bandwidth, O(ns·kd·m), and J = J0 − Φ_Sᵀ Vᵀ O(ns·m²).
   subroutine ritz_newton_solve(self, info)
      class(fast_nonlinear_t), intent(inout) :: self
      integer, intent(out) :: info
      real(dp) :: jac(self%nm, self%nm), dk, dc
      integer :: i, j, lo, a, b, kd, r
      kd = self%kband%kd; r = 2*kd + 1
      self%vtr = 0.0_dp
      lo = 1
      associate (s => self%sdof, ns => self%ns)
         do j = 1, ns
            b = self%free(s(j))
            do while (self%free(s(lo)) < b - kd)
               lo = lo + 1
            end do
            do i = lo, ns
               a = self%free(s(i))
               if (a > b + kd) exit
               dk = self%kband%ab(r + a - b, b) - self%klb%ab(r + a - b, b)
               dc = self%cband%ab(r + a - b, b) - self%clb%ab(r + a - b, b)
               if (dk == 0.0_dp .and. dc == 0.0_dp) cycle
               self%vtr(i, :) = self%vtr(i, :) + self%phis(j, :)*(dk*self%g1q + dc*self%g1v)
            end do
         end do
      end associate
      jac = self%jr - matmul(transpose(self%phis), self%vtr)
      self%y = -self%r
      call dgesv(self%nm, 1, jac, self%nm, self%ipiv, self%y, self%nm, info)
   end subroutine ritz_newton_solve

   !> One step: the modal states advanced exactly for p linear over the step, p at the end
   !> iterated to its fixed point; works, counters, contact state.
   subroutine step(self, m, t, o, stat)
      class(fast_nonlinear_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: it, info, halvings
      real(dp) :: change, scale, wd, wl, wc, previous
      logical :: newton, stepped
      character(len=256) :: msg
      stat = MARTELLO_OK
      self%qn = self%q; self%qdn = self%qd; self%pn = self%p
      self%fext_n = self%fext
      call external_forces(m, self%mrow, t, self%fext)
      self%ptrial = self%pn                     ! predictor: the load of the step's start
      newton = .false.; previous = huge(1.0_dp); change = 0.0_dp; scale = 1.0_dp; halvings = 0
      stepped = .false.            ! a Newton step has been taken (it may be halved)
      do it = 1, self%max_iter
         self%q = self%e11*self%qn + self%e12*self%qdn + self%g0q*self%pn + self%g1q*self%ptrial
         self%qd = self%e21*self%qn + self%e22*self%qdn + self%g0v*self%pn + self%g1v*self%ptrial
         call to_nodes(self)
         if (newton) then
            call band_zero(self%kband); call band_zero(self%cband)
            call internal_forces(m, self%ms, self%u, self%v, self%fint, self%kband%ab, 1.0_dp, &
                                 0.0_dp, self%cband%ab)
         else
            call internal_forces(m, self%ms, self%u, self%v, self%fint)
         end if
         o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
         o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
         self%p = matmul(transpose(self%phi), self%fext(self%free) - self%fint(self%free)) + &
                  self%w2*self%q + self%c*self%qd
         self%r = self%p - self%ptrial
         change = maxval(abs(self%r))
         ! p is the difference of the internal force and ω²q + cq̇: its round-off is relative
         ! to those terms, not to p (small in free vibration)
         scale = max(maxval(abs(self%p)), maxval(abs(self%w2*self%q)), &
                     maxval(abs(self%c*self%qd)), tiny(1.0_dp))
         if (self%nf == 0) change = 0.0_dp
         if (.not. (change == change)) exit        ! NaN: reported below
         if (change <= self%tol*scale) then
            ! converged: the state is the one f_int was evaluated at, p its load
            call set_acceleration(self)
            call mech_commit(m, self%ms, self%u, wd, wl, wc)
            call observer_work(o, damping=wd, links=wl, contact=wc)
            call observer_work(o, external=external_work(m, self%fext_n, self%fext, self%un, self%u))
            call contact_state(self, m)
            return
         end if
         if (newton) then
            ! a Newton step that raised the residual is halved (a damper law |v|^α with α < 1
            ! makes full steps overshoot and cycle)
            if (stepped .and. change > previous .and. halvings < 30) then
               halvings = halvings + 1
               self%dp = 0.5_dp*self%dp
               self%ptrial = self%pbase + self%dp
               cycle
            end if
            halvings = 0
            call newton_update(info)
            if (info /= 0) exit
            stepped = .true.
         else
            self%ptrial = self%p
            ! Wilson's iteration contracts by about h²k/m per pass: slower than 1/4, Newton
            if (it >= 2 .and. change > 0.25_dp*previous) newton = .true.
         end if
         previous = change
      end do
      write (msg, '(a,i0,a,a,a)') 'fast-nonlinear: the pseudo-force iteration did not converge in ', &
         self%max_iter, ' iterations (last relative change ', sci(change/scale, 2), &
         '); reduce dt or raise max_newton'
      call stepper_fail(o, MARTELLO_ERR_NOT_CONVERGED, t, trim(msg), stat)

   contains
      !> ptrial ← ptrial − J⁻¹ r with J = ∂P/∂p − I at the state just evaluated:
      !> ∂P/∂q = diag(ω²) − Φᵀ K_t Φ = −Φ(S,:)ᵀ ΔK Φ(S,:) and ∂P/∂q̇ = −Coff − Φ(S,:)ᵀ ΔC Φ(S,:)
      !> (ΔK = K_t − K_L, ΔC = C_t − C_L: nonzero on S only), ∂q/∂p = g1q, ∂q̇/∂p = g1v. So
      !> J = J0 − U Vᵀ, U = Φ(S,:)ᵀ, Vᵀ = ΔK Φ(S,:) G1q + ΔC Φ(S,:) G1v, and
      !> J⁻¹ = J0⁻¹ + W (I − Vᵀ W)⁻¹ Vᵀ J0⁻¹ (Woodbury), W = J0⁻¹U.
      subroutine newton_update(info)
         integer, intent(out) :: info
         integer :: i, j, kd, a, b
         kd = self%kband%kd
         if (self%ritz) then
            o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
            o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
            call ritz_newton_solve(self, info)
            if (info /= 0) return
            self%pbase = self%ptrial; self%dp = self%y
            self%ptrial = self%pbase + self%dp
            return
         end if
         associate (s => self%sdof, ns => self%ns)
            do j = 1, ns
               do i = 1, ns
                  a = self%free(s(i)); b = self%free(s(j))
                  self%dks(i, j) = -self%kls(i, j); self%dcs(i, j) = -self%cls(i, j)
                  if (abs(a - b) > kd) cycle
                  self%dks(i, j) = self%dks(i, j) + self%kband%ab(2*kd + 1 + a - b, b)
                  self%dcs(i, j) = self%dcs(i, j) + self%cband%ab(2*kd + 1 + a - b, b)
               end do
            end do
            do j = 1, self%nf
               self%vt(:, j) = matmul(self%dks, self%phis(:, j))*self%g1q(j) + &
                               matmul(self%dcs, self%phis(:, j))*self%g1v(j)
            end do
            o%counters(C_JACOBIANS) = o%counters(C_JACOBIANS) + 1_i8
            o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
            self%y = -self%r
            call dgetrs('N', self%nf, 1, self%j0, self%nf, self%ipiv, self%y, self%nf, info)
            if (info /= 0) return
            if (ns > 0) then
               self%small = -matmul(self%vt, self%w)
               do i = 1, ns
                  self%small(i, i) = self%small(i, i) + 1.0_dp
               end do
               self%z = matmul(self%vt, self%y)
               call dgesv(ns, 1, self%small, ns, self%ipiv_s, self%z, ns, info)
               if (info /= 0) return
               self%y = self%y + matmul(self%w, self%z)
            end if
         end associate
         self%pbase = self%ptrial; self%dp = self%y
         self%ptrial = self%pbase + self%dp
      end subroutine newton_update
   end subroutine step

   !> u, v on the nodes from the modal state (fixed nodes at u0 and at rest).
   subroutine to_nodes(self)
      class(fast_nonlinear_t), intent(inout) :: self
      self%u(self%free) = matmul(self%phi, self%q)
      self%v(self%free) = matmul(self%phi, self%qd)
      self%u(0) = 0.0_dp; self%v(0) = 0.0_dp
   end subroutine to_nodes

   !> a = Φ q̈ with q̈ = p − c∘q̇ − ω²∘q: the equations of motion at the state.
   subroutine set_acceleration(self)
      class(fast_nonlinear_t), intent(inout) :: self
      real(dp) :: qdd(size(self%q))
      ! q̈ first (in the matmul, the expression made gfortran warn of an uninitialised
      ! temporary's descriptor)
      qdd = self%p - self%c*self%qd - self%w2*self%q
      self%a = 0.0_dp
      self%a(self%free) = matmul(self%phi, qdd)
   end subroutine set_acceleration

   !> The exact step of q̈ + c q̇ + ω² q = p(τ), p linear on [0, h]: (q, q̇)(h) =
   !> E (q, q̇)(0) + G0 p(0) + G1 p(h), from the exponential of the augmented system
   !> y = (s q, q̇, p, Δp), ẏ = H y with ṗ = Δp/h (Van Loan 1978), s = max(ω, 1/h) balancing
   !> the first two rows (so ω = 0 and every damping ratio are covered by one formula).
   pure subroutine modal_step_coefficients(w2, c, h, e11, e12, e21, e22, g0q, g0v, g1q, g1v)
      real(dp), intent(in) :: w2, c, h
      real(dp), intent(out) :: e11, e12, e21, e22, g0q, g0v, g1q, g1v
      real(dp) :: hm(4, 4), x(4, 4), sc
      sc = max(sqrt(w2), 1.0_dp/h)
      hm = 0.0_dp
      hm(1, 2) = sc                 ! d(s q)/dt = s q̇
      hm(2, 1) = -w2/sc             ! dq̇/dt = −ω² q − c q̇ + p
      hm(2, 2) = -c
      hm(2, 3) = 1.0_dp
      hm(3, 4) = 1.0_dp/h
      call expm4(h*hm, x)
      e11 = x(1, 1); e12 = x(1, 2)/sc; e21 = x(2, 1)*sc; e22 = x(2, 2)
      ! p(τ) = p0 + Δp τ/h: columns 3 (p0) and 4 (Δp = p1 − p0)
      g0q = (x(1, 3) - x(1, 4))/sc; g1q = x(1, 4)/sc
      g0v = x(2, 3) - x(2, 4); g1v = x(2, 4)
   end subroutine modal_step_coefficients

   !> exp(a) of a 4 × 4 matrix: scaling and squaring with a degree-18 Taylor polynomial
   !> (‖a/2^k‖₁ ≤ 1/2: truncation below 1e-20, Moler & Van Loan 2003, method 3).
   pure subroutine expm4(a, x)
      real(dp), intent(in) :: a(4, 4)
      real(dp), intent(out) :: x(4, 4)
      real(dp) :: b(4, 4), term(4, 4), nrm
      integer :: k, sq, i
      nrm = maxval(sum(abs(a), dim=1))
      sq = 0
      if (nrm > 0.5_dp) sq = ceiling(log(nrm/0.5_dp)/log(2.0_dp))
      b = a/2.0_dp**sq
      x = 0.0_dp
      do i = 1, 4
         x(i, i) = 1.0_dp
      end do
      term = x
      do k = 1, 18
         term = matmul(term, b)/real(k, dp)
         x = x + term
      end do
      do k = 1, sq
         x = matmul(x, x)
      end do
   end subroutine expm4
end module martello_fast_nonlinear
