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
!> tangents in modal coordinates (counted as jacobian_evaluations). All modes are kept: the
!> linear part is then exact and the only error is the linear interpolation of the
!> pseudo-forces over the step, O(h²).
module martello_fast_nonlinear
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t
   use martello_element_rows, only: rows_t, row_lo, row_hi
   use martello_links, only: LINK_SPRING, LINK_BAR, LINK_DASHPOT, LINK_BILINEAR, L_STIFF, L_DAMP
   use martello_assembly, only: internal_forces, external_forces, mech_commit, external_work, &
      mass_times
   use martello_observer, only: observer_t, observer_work, observer_fail
   use martello_run_quantities, only: C_MODES, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_JACOBIANS
   use martello_integrator_settings, only: integrator_settings_t
   use martello_fixed_step, only: stepper_t, stepper_start, stepper_fail, contact_state
   use martello_lapack, only: dsygv, dgesv, dgetrf, dgetrs
   use martello_links, only: LINK_FLUID_DAMPER
   use martello_model, only: SCHEME_PENALTY
   use martello_model, only: model_bandwidth
   use martello_band_matrix, only: band_t, band_init, band_zero
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
      integer :: nf = 0, max_iter = 30
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
      integer :: n, nf, i, j, info, lwork
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
      if (stat == MARTELLO_OK) then
         self%nf = nf
         self%free = pack([(i, i = 1, n)], .not. m%fixed)
         ! the dense modal matrices (K_L, C_L, M and Φ: nf² each) and every per-mode array
         allocate (self%fint(0:n), self%fext(0:n), self%fext_n(0:n), x(0:n), y(0:n), &
                   kl(nf, nf), cl(nf, nf), mm(nf, nf), self%phi(nf, nf), self%w2(nf), self%c(nf), &
                   self%e11(nf), self%e12(nf), self%e21(nf), self%e22(nf), self%g0q(nf), &
                   self%g0v(nf), self%g1q(nf), self%g1v(nf), self%q(nf), self%qd(nf), self%qn(nf), &
                   self%qdn(nf), self%p(nf), self%pn(nf), self%ptrial(nf), self%r(nf), &
                   self%pbase(nf), self%dp(nf), work(1), stat=stat)
         if (stat /= 0) call modal_memory('the modal matrices of fast-nonlinear', &
                                          REAL_BYTES*(5*(n + 1.0_dp) + 4*real(nf, dp)**2 + 20.0_dp*nf + 1))
      end if
      if (stat == MARTELLO_OK) call band_init(self%kband, n, model_bandwidth(m), stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%cband, n, model_bandwidth(m), stat, msg)
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      call linear_part(m, dof, kl, cl)
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
      do i = 1, nf
         call modal_step_coefficients(self%w2(i), self%c(i), self%h, self%e11(i), self%e12(i), &
                                      self%e21(i), self%e22(i), self%g0q(i), self%g0v(i), &
                                      self%g1q(i), self%g1v(i))
      end do
      call newton_setup(self, m, dof, kl, cl, info, msg)
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
      logical :: touched(self%nf)
      integer :: j, nf
      character(len=96) :: what
      real(dp), allocatable :: coff(:, :)
      nf = self%nf
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
      self%sdof = pack([(j, j = 1, nf)], touched)
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
   end subroutine newton_setup

   !> K_L and C_L of the linear part on the free DOFs (dof: node → DOF, 0 for fixed/ground).
   subroutine linear_part(m, dof, kl, cl)
      type(model_t), intent(in) :: m
      integer, intent(in) :: dof(0:)
      real(dp), intent(out) :: kl(:, :), cl(:, :)
      integer :: j, p, q
      kl = 0.0_dp; cl = 0.0_dp
      do j = 1, m%nlink
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR, LINK_BILINEAR)
            call add_row(kl, j, m%link_par(L_STIFF, j))
         case (LINK_DASHPOT)
            call add_row(cl, j, m%link_par(L_DAMP, j))
         end select
      end do
      do j = 1, m%nblock
         associate (nd => m%block(j)%node)
            do q = 1, size(nd)
               do p = 1, size(nd)
                  if (dof(nd(p)) > 0 .and. dof(nd(q)) > 0) then
                     kl(dof(nd(p)), dof(nd(q))) = kl(dof(nd(p)), dof(nd(q))) + m%block(j)%k(p, q)
                     cl(dof(nd(p)), dof(nd(q))) = cl(dof(nd(p)), dof(nd(q))) + m%block(j)%c(p, q)
                  end if
               end do
            end do
         end associate
      end do
   contains
      !> a += val gᵀg over link j's row on the free DOFs.
      subroutine add_row(a, j, val)
         real(dp), intent(inout) :: a(:, :)
         integer, intent(in) :: j
         real(dp), intent(in) :: val
         integer :: p, q, ip, iq
         do p = row_lo(m%lnk, j), row_hi(m%lnk, j)
            ip = dof(m%lnk%node(p))
            do q = row_lo(m%lnk, j), row_hi(m%lnk, j)
               iq = dof(m%lnk%node(q))
               if (ip > 0 .and. iq > 0) a(ip, iq) = a(ip, iq) + val*m%lnk%coef(p)*m%lnk%coef(q)
            end do
         end do
      end subroutine add_row
   end subroutine linear_part

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
