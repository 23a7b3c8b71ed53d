!> The seed's Newmark–Lagrange scheme (Papadrakakis et al. 1991; seed eq. 48; docs/problems.md
!> "Lagrange + Newmark"): Newmark time stepping with the contact constraint δ = 0 enforced at
!> the displacement level by a Lagrange multiplier, and (β, γ) re-chosen in every step that
!> contains an impact so that the relative velocity at the end of that step is −e times the
!> approach speed.
!>
!> Derivation (docs/moreau-jean.md). For the relative coordinate δ of the impacting contact,
!> Newmark with δ_{n+1} = 0 gives δ̈_{n+1} = −D(β)/(βh²), D(β) = δ_n + hδ̇_n + h²(½ − β)δ̈_n, so
!>
!>   δ̇_{n+1} = δ̇_n + hδ̈_n − γ D₀/(βh),   D₀ = δ_n + hδ̇_n + ½h²δ̈_n
!>
!> (D₀: the penetration free flight would reach at the step end). Asking δ̇_{n+1} = −e v_imp,
!> with v_imp = δ̇_n + αhδ̈_n the approach speed at the instant t_n + αh where the gap closes,
!> fixes only the ratio
!>
!>   γ/β = R = h (δ̇_n + hδ̈_n + e v_imp)/D₀     (= (1 + e)/(1 − α) when δ̈_n = 0, which is
!>                                               docs/problems.md's "γ(1 − α)/β − 1 = e").
!>
!> We keep γ = ½ (no numerical damping) and take β = 1/(2R). The pair is unconditionally
!> stable (2β ≥ γ ≥ ½) iff R ≤ 2, i.e. α ≤ (1 − e)/2 without other forces; otherwise the
!> impact step is stable for ωh < 1/√(¼ − β) (≥ 2, the central-difference limit).
!> The multiplier carries the impulse as a force ~ m* v (1 + e)/h; after the impact step the
!> acceleration is reset from equilibrium (the impulsive a_{n+1} must not enter the next
!> Newmark predictor). Steps without impacts use β = ¼, γ = ½ with the persistent contacts
!> (plastic impacts, Zeno) held by the multiplier, released when it turns tensile.
!> Zeno: an impact whose next rebound flight, at the pressing relative acceleration, would be
!> shorter than one step (the accumulation policy of docs/impulse.md §4 with the step as time
!> resolution, martello_impulse's impulse_accumulation) is made plastic and the contact
!> persistent.
!> Dense KKT solves (LAPACK dsytrf): a scheme for the small problems P2 and P5.
!>
!> A stepper of the fixed-step strategy (martello_fixed_step, docs/run-layer.md).
module martello_newmark_lagrange
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_bandwidth, rigid_contacts
   use martello_element_rows, only: row_dot, row_add, row_lo, row_hi
   use martello_band_matrix, only: band_t, band_init
   use martello_assembly, only: internal_forces, external_forces, mech_commit, mass_times, &
      external_work
   use martello_observer, only: observer_t, observer_work, observer_fail, observer_open_phase, &
      observer_close_phase, free_side_crossing
   use martello_run_quantities, only: C_REJECTED, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_EVENTS
   use martello_integrator_settings, only: integrator_settings_t
   use martello_fixed_step, only: stepper_t, stepper_start, newmark_predictor, newmark_increment, &
      contact_state
   use martello_linalg, only: solve_symmetric_indefinite
   use martello_impulse, only: impulse_accumulation
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: newmark_lagrange_t, NL_MAX_NODES

   !> Dense KKT systems: refuse scenes beyond this size (the scheme is meant for P2 and P5).
   integer, parameter :: NL_MAX_NODES = 500

   type, extends(stepper_t) :: newmark_lagrange_t
      integer :: kd = 0, max_newton = 30
      real(dp) :: tol_residual = 0.0_dp, tol_increment = 0.0_dp
      real(dp), allocatable :: fint(:), fint_n(:), fext(:), fext_n(:), ma(:), work(:), mdense(:, :)
      real(dp), allocatable :: e_con(:), lam(:), mstar(:)
      logical, allocatable :: pers(:), active(:), movable(:), rigid(:)
      type(band_t) :: kband, cband
   contains
      procedure :: init
      procedure :: step
   end type newmark_lagrange_t

contains

   !> The state at t = 0 with the acceleration from equilibrium, the dense mass matrix and
   !> the effective mass of every contact.
   subroutine init(self, m, s, o, stat)
      class(newmark_lagrange_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      type(integrator_settings_t), intent(in) :: s
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, nc, i
      logical :: converged
      character(len=16) :: num
      character(len=256) :: msg
      stat = MARTELLO_OK
      if (m%n > NL_MAX_NODES) then
         write (num, '(i0)') NL_MAX_NODES
         call observer_fail(o, MARTELLO_ERR_UNSUPPORTED, 0.0_dp, &
                            'newmark-lagrange solves dense KKT systems and is meant for small problems'// &
                            ' (P2, P5): at most '//trim(num)//' nodes; use moreau-jean for chains', stat)
         return
      end if
      call stepper_start(self, m, s, o, stat)
      if (stat /= MARTELLO_OK) return
      n = m%n; nc = m%ncontact
      self%advice = 'reduce dt'
      self%kd = model_bandwidth(m)
      self%max_newton = s%max_newton
      self%tol_residual = s%tol_residual; self%tol_increment = s%tol_increment
      allocate (self%fint(0:n), self%fint_n(0:n), self%fext(0:n), self%fext_n(0:n), &
                self%ma(0:n), self%work(0:n), self%mdense(n, n), &
                self%e_con(nc), self%lam(nc), self%mstar(nc), &
                self%rigid(nc), self%pers(nc), self%active(nc), self%movable(nc), stat=stat)
      if (stat /= 0) call out_of_memory('the state of Newmark-Lagrange', REAL_BYTES*(6*(n + 1.0_dp) &
                                        + real(n, dp)**2 + 3*nc) + INT_BYTES*6.0_dp*nc, &
                                        FIX_SMALLER_SCENE, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%kband, n, self%kd, stat, msg)
      if (stat == MARTELLO_OK) call band_init(self%cband, n, self%kd, stat, msg)
      if (stat /= MARTELLO_OK) then
         call observer_fail(o, MARTELLO_ERR_MEMORY, 0.0_dp, msg, stat)
         return
      end if
      self%pers = .false.; self%lam = 0.0_dp

      ! dense mass matrix (lumped diagonal and consistent couplings), columns by M e_i
      do i = 1, n
         self%work = 0.0_dp; self%work(i) = 1.0_dp
         call mass_times(m, self%work, self%ma)
         self%mdense(:, i) = self%ma(1:n)
      end do
      call rigid_contacts(m, self%rigid, self%e_con, self%movable)
      ! the model's effective mass of each contact, 1/(B M⁻¹ Bᵀ) (martello_effective_mass),
      ! for the impact energy loss; 0 where neither side moves
      self%mstar = merge(m%con_mstar(1:nc), 0.0_dp, self%movable)

      call internal_forces(m, self%ms, self%u, self%v, self%fint)
      call mech_commit(m, self%ms, self%u)
      call external_forces(m, self%mrow, 0.0_dp, self%fext)
      call equilibrium_acceleration(self, m, 0.0_dp, o, converged, stat)
      if (.not. converged) return
      call contact_state(self, m, self%lam)
   end subroutine init

   !> a from M a = f_ext − fint + Bᵀλ with B a = 0 on the persistent contacts (their λ the
   !> contact forces of the state).
   subroutine equilibrium_acceleration(self, m, t, o, ok, stat)
      class(newmark_lagrange_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      logical, intent(out) :: ok
      integer, intent(inout) :: stat
      integer :: n, na, j, st, idx(m%ncontact)
      real(dp), allocatable :: kkt(:, :), rhs(:)
      real(dp) :: rc
      character(len=256) :: msg
      n = self%n
      associate (fixed_nodes => self%fixed_nodes)
         na = 0
         do j = 1, m%ncontact
            if (self%pers(j) .and. self%movable(j)) then
               na = na + 1; idx(na) = j
            end if
         end do
         ok = .false.
         allocate (kkt(n + na, n + na), rhs(n + na), stat=st)
         if (st /= 0) then
            call out_of_memory('the KKT system of Newmark-Lagrange', REAL_BYTES*(n + na + 1.0_dp)*(n + na), &
                               FIX_SMALLER_SCENE, st, msg)
            call observer_fail(o, MARTELLO_ERR_MEMORY, t, msg, stat)
            return
         end if
         kkt = 0.0_dp
         kkt(1:n, 1:n) = self%mdense
         rhs = 0.0_dp
         rhs(1:n) = self%fext(1:n) - self%fint(1:n)
         call kkt_constraints(self, m, kkt, idx, na)
         rhs(fixed_nodes) = 0.0_dp
         call solve_symmetric_indefinite(kkt, rhs, rc, st, msg)
         o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
         ok = st == MARTELLO_OK
         if (st == MARTELLO_ERR_MEMORY) then
            call observer_fail(o, st, t, msg, stat)
            return
         else if (.not. ok) then
            call observer_fail(o, st, t, 'Newmark-Lagrange: the mass matrix with the persistent'// &
                               ' contacts is singular ('//trim(msg)//')', stat)
            return
         end if
         self%a(0) = 0.0_dp
         self%a(1:n) = rhs(1:n)
         self%a(fixed_nodes) = 0.0_dp
         self%lam = 0.0_dp
         do j = 1, na
            self%lam(idx(j)) = rhs(n + j)
         end do
      end associate
   end subroutine equilibrium_acceleration

   !> In a KKT matrix of order n + na: the rows and columns ±1 of the active contacts idx(1:na)
   !> (B and Bᵀ), and the identity on the fixed nodes.
   subroutine kkt_constraints(self, m, kkt, idx, na)
      class(newmark_lagrange_t), intent(in) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(inout) :: kkt(:, :)
      integer, intent(in) :: idx(:), na
      integer :: j, k, n, i, q
      n = self%n
      do j = 1, na
         k = idx(j)
         ! the row's terms (on fixed nodes too: their rows and columns are reset below)
         do q = row_lo(m%con, k), row_hi(m%con, k)
            kkt(m%con%node(q), n + j) = kkt(m%con%node(q), n + j) + m%con%coef(q)
            kkt(n + j, m%con%node(q)) = kkt(n + j, m%con%node(q)) + m%con%coef(q)
         end do
      end do
      do j = 1, size(self%fixed_nodes)
         i = self%fixed_nodes(j)
         kkt(i, :) = 0.0_dp; kkt(:, i) = 0.0_dp
         kkt(i, i) = 1.0_dp
      end do
   end subroutine kkt_constraints

   !> One step: the trial with the persistent contacts held, then, if a free contact closed,
   !> the impact step with (β, γ) tuned to Newton's law; works and phases to the observer.
   subroutine step(self, m, t, o, stat)
      class(newmark_lagrange_t), intent(inout) :: self
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      type(observer_t), intent(inout) :: o
      integer, intent(out) :: stat
      integer :: n, nc, c, ci, attempt, imp_c
      real(dp) :: h, t_prev, beta, gamma, wdl, wll, wcl, alpha_imp, v_imp, e_eff, rr, d0, dd0, &
                  ddd0, tau, best_alpha, lam_tol, t_inf
      logical :: converged, impact, released, zeno
      character(len=256) :: msg
      character(len=320) :: why

      stat = MARTELLO_OK
      n = self%n; nc = self%nc; h = self%h
      t_prev = self%t0
      associate (u => self%u, v => self%v, un => self%un, vn => self%vn, an => self%an, &
                 fint => self%fint, fext => self%fext, pers => self%pers, active => self%active, &
                 movable => self%movable, lam => self%lam, e_con => self%e_con)
         self%fint_n = fint; self%fext_n = fext
         call external_forces(m, self%mrow, t, fext)

         ! 1. trial step, average acceleration, persistent contacts held; release tensile ones
         beta = 0.25_dp; gamma = 0.5_dp
         do attempt = 1, nc + 1
            active = pers
            call newmark_solve(beta, gamma, converged)
            if (.not. converged) return
            released = .false.
            ! tensile beyond the rounding of the step's force balance (~ε·m v/h)
            lam_tol = 64.0_dp*epsilon(1.0_dp)*(maxval(abs(fext)) + maxval(abs(fint)) + &
                                               maxval(m%mass)*maxval(abs(v))/h)
            do c = 1, nc
               if (pers(c) .and. lam(c) < -lam_tol) then
                  pers(c) = .false.; released = .true.
               end if
            end do
            if (.not. released) exit
            o%counters(C_REJECTED) = o%counters(C_REJECTED) + 1_i8
         end do

         ! 2. a free contact that the trial closed: the earliest one sets (β, γ) for the step
         impact = .false.; imp_c = 0; best_alpha = huge(1.0_dp)
         do c = 1, nc
            if (.not. movable(c) .or. pers(c)) cycle
            if (row_dot(m%con, c, u) - m%con_gap(c) > closed_tol(c)) then
               d0 = row_dot(m%con, c, un) - m%con_gap(c)
               dd0 = row_dot(m%con, c, vn)
               ddd0 = row_dot(m%con, c, an)
               tau = 0.0_dp
               if (d0 < 0.0_dp) tau = free_side_crossing(d0, dd0, ddd0, 0.0_dp, h)
               if (tau/h < best_alpha) then
                  best_alpha = tau/h; imp_c = c
               end if
            end if
         end do
         if (imp_c > 0) then
            impact = .true.
            o%counters(C_REJECTED) = o%counters(C_REJECTED) + 1_i8
            c = imp_c
            alpha_imp = best_alpha
            d0 = row_dot(m%con, c, un) - m%con_gap(c)
            dd0 = row_dot(m%con, c, vn)
            ddd0 = row_dot(m%con, c, an)
            v_imp = dd0 + alpha_imp*h*ddd0
            e_eff = e_con(c)
            ! Zeno: the next rebound flight under the pressing acceleration δ̈_n is shorter than
            ! a step, the scheme's time resolution (one impact a step is what the tuned (β, γ)
            ! resolve; positions and speeds it keeps to round-off); it writes no t∞, so the
            ! change of δ̈ over the flight does not enter (da = 0)
            call impulse_accumulation(e_eff, e_eff*max(v_imp, 0.0_dp), ddd0, 0.0_dp, &
                                      t_prev + alpha_imp*h, h, 0.0_dp, 0.0_dp, .false., zeno, t_inf)
            if (zeno) e_eff = 0.0_dp
            rr = h*(dd0 + h*ddd0 + e_eff*v_imp)/(d0 + h*dd0 + 0.5_dp*h*h*ddd0)
            if (.not. (rr > 0.0_dp .and. ieee_is_finite(rr)) .or. v_imp <= 0.0_dp) then
               ! a graze (no approach speed): hold it as a persistent contact
               e_eff = 0.0_dp
               beta = 0.25_dp; gamma = 0.5_dp
            else
               gamma = 0.5_dp; beta = 1.0_dp/(2.0_dp*rr)
            end if
            active = pers
            do ci = 1, nc
               if (movable(ci) .and. .not. pers(ci) .and. &
                   row_dot(m%con, ci, u) - m%con_gap(ci) > closed_tol(ci)) active(ci) = .true.
            end do
            call newmark_solve(beta, gamma, converged)
            if (.not. converged) return
            if (e_eff == 0.0_dp) pers(c) = .true.
            do ci = 1, nc      ! other contacts closed in the same step: held from now on
               if (ci /= c .and. active(ci) .and. .not. pers(ci)) pers(ci) = .true.
            end do
            call observer_work(o, impact=0.5_dp*self%mstar(c)*(v_imp**2 - (row_dot(m%con, c, v))**2))
         end if

         call mech_commit(m, self%ms, u, wdl, wll, wcl)
         call observer_work(o, damping=wdl, links=wll, contact=wcl)
         call observer_work(o, external=external_work(m, self%fext_n, fext, un, u))
      end associate
      call contact_state(self, m, self%lam)
      call phases()
      ! the impulsive acceleration of an impact step must not enter the next predictor
      if (impact) call equilibrium_acceleration(self, m, t, o, converged, stat)

   contains

      !> A contact counts as closed by the trial beyond the rounding of its gap: the constraint
      !> of an impact step leaves δ_{n+1} = 0 only to a few ulps of the coordinates.
      real(dp) function closed_tol(cc)
         integer, intent(in) :: cc
         integer :: k
         closed_tol = abs(m%con_gap(cc))
         do k = row_lo(m%con, cc), row_hi(m%con, cc)
            closed_tol = closed_tol + abs(m%con%coef(k)*self%u(m%con%node(k)))
         end do
         closed_tol = 8.0_dp*epsilon(1.0_dp)*closed_tol
      end function closed_tol

      !> Newton on the constrained Newmark step: unknowns u_{n+1} and the multipliers λ of
      !> the active contacts; KKT matrix [J −Bᵀ; −B 0], J = M/(βh²) + γ/(βh) C + K.
      !> From the constant-acceleration predictor, u, v, a and λ move together by each
      !> increment (newmark_increment), and so does each active constraint's δ_{n+1}: from the
      !> predictor's D₀ = δ_n + hδ̇_n + ½h²δ̈_n (δ_n = 0 for a contact held since the last
      !> step, its constraint's; the stored gap otherwise) by B Δu. Neither a nor δ_{n+1} is
      !> read back from u, whose rounding ε|u| would be an acceleration ε|u|/(βh²)
      !> (docs/moreau-jean.md §2, "Rounding").
      subroutine newmark_solve(bt, gm, ok)
         real(dp), intent(in) :: bt, gm
         logical, intent(out) :: ok
         integer :: it, na, j, k, q, row, col, st, idx(nc)
         real(dp), allocatable :: kkt(:, :), rhs(:)
         real(dp) :: rnorm, cnorm, fscale, uscale, rc, delta(nc), d_n
         associate (u => self%u, un => self%un, vn => self%vn, an => self%an, a => self%a, &
                    v => self%v, fint => self%fint, fext => self%fext, ma => self%ma, &
                    lam => self%lam, kd => self%kd, &
                    kband => self%kband, cband => self%cband, fixed_nodes => self%fixed_nodes)
            na = 0
            do j = 1, nc
               if (self%active(j)) then
                  na = na + 1; idx(na) = j
               end if
            end do
            ok = .false.
            allocate (kkt(n + na, n + na), rhs(n + na), stat=st)
            if (st /= 0) then
               call out_of_memory('the KKT system of Newmark-Lagrange', &
                                  REAL_BYTES*(n + na + 1.0_dp)*(n + na), FIX_SMALLER_SCENE, st, msg)
               call observer_fail(o, MARTELLO_ERR_MEMORY, t_prev, msg, stat)
               return
            end if
            lam = 0.0_dp
            call newmark_predictor(self)
            do j = 1, na
               k = idx(j)
               d_n = 0.0_dp
               if (.not. self%pers(k)) d_n = row_dot(m%con, k, un) - m%con_gap(k)
               ! the expression of the impact's D₀ in step (the same number: the tuned ratio
               ! γ/β then leaves δ̇_{n+1} = −e v_imp to the rounding of the arithmetic)
               delta(j) = d_n + h*row_dot(m%con, k, vn) + 0.5_dp*h*h*row_dot(m%con, k, an)
            end do
            uscale = tiny(1.0_dp)
            do k = 1, n
               uscale = max(uscale, abs(un(k)), h*abs(vn(k)), h*h*abs(an(k)))
            end do
            ok = .false.
            do it = 0, self%max_newton
               kband%ab = 0.0_dp; cband%ab = 0.0_dp
               call internal_forces(m, self%ms, u, v, fint, kband%ab, 1.0_dp, 0.0_dp, cband%ab)
               o%counters(C_RESIDUALS) = o%counters(C_RESIDUALS) + 1_i8
               call mass_times(m, a, ma)
               rhs = 0.0_dp
               rhs(1:n) = ma(1:n) + fint(1:n) - fext(1:n)
               do j = 1, na
                  k = idx(j)
                  do q = row_lo(m%con, k), row_hi(m%con, k)
                     rhs(m%con%node(q)) = rhs(m%con%node(q)) + m%con%coef(q)*lam(k)
                  end do
                  rhs(n + j) = delta(j)
               end do
               rhs(fixed_nodes) = 0.0_dp
               rnorm = maxval(abs(rhs(1:n)))
               cnorm = 0.0_dp
               if (na > 0) cnorm = maxval(abs(rhs(n + 1:n + na)))
               fscale = max(maxval(abs(fext(1:n))), maxval(abs(fint(1:n))), maxval(abs(ma(1:n))), &
                            maxval(abs(lam)), tiny(1.0_dp))
               ! not asked for: a residual below the inertia of an ulp of u, ε·m|u|/(βh²) (the
               ! test in displacement units of the generalized-α family, docs/integrators.md)
               fscale = max(fscale, 64.0_dp*epsilon(1.0_dp)/self%tol_residual*maxval(m%mass)*uscale/(bt*h*h))
               if (it > 0 .and. rnorm <= self%tol_residual*fscale .and. &
                   cnorm <= max(self%tol_increment*max(uscale, maxval(abs(u))), &
                                16.0_dp*epsilon(1.0_dp)*maxval(abs(u)))) then
                  ok = .true.
                  exit
               end if
               if (it == self%max_newton) exit
               ! KKT matrix
               kkt = 0.0_dp
               kkt(1:n, 1:n) = self%mdense/(bt*h*h)
               do col = 1, n
                  do row = max(1, col - kd), min(n, col + kd)
                     kkt(row, col) = kkt(row, col) + kband%ab(2*kd + 1 + row - col, col) + &
                                     gm/(bt*h)*cband%ab(2*kd + 1 + row - col, col)
                  end do
               end do
               call kkt_constraints(self, m, kkt, idx, na)
               rhs = -rhs
               call solve_symmetric_indefinite(kkt, rhs, rc, st, msg)
               o%counters(C_FACTORIZATIONS) = o%counters(C_FACTORIZATIONS) + 1_i8
               o%counters(C_NEWTON) = o%counters(C_NEWTON) + 1_i8
               if (st == MARTELLO_ERR_MEMORY) then
                  call observer_fail(o, st, t_prev, msg, stat)
                  return
               else if (st /= MARTELLO_OK) then
                  write (why, '(a,a,a)') 'Newmark-Lagrange: singular KKT system at t = ', sci(t, 5), &
                     ' s ('//trim(msg)//')'
                  call observer_fail(o, st, t_prev, why, stat)
                  return
               end if
               call newmark_increment(self, rhs(1:n), bt, gm)
               self%work(0) = 0.0_dp; self%work(1:n) = rhs(1:n)
               do j = 1, na
                  lam(idx(j)) = lam(idx(j)) + rhs(n + j)
                  delta(j) = delta(j) + row_dot(m%con, idx(j), self%work)
               end do
            end do
            if (.not. ok) then
               write (msg, '(a,a,a,i0,a)') 'Newmark-Lagrange: Newton did not converge at t = ', &
                  sci(t, 5), ' s after ', self%max_newton, ' iterations; reduce dt'
               call observer_fail(o, MARTELLO_ERR_NOT_CONVERGED, t_prev, msg, stat)
            end if
         end associate
      end subroutine newmark_solve

      !> Phases: an impact opens one at t_n + αh with v_imp; an elastic/partly elastic
      !> impact closes it at once (v_out = δ̇_{n+1}), a plastic one stays open while the
      !> contact is held and closes at the release step.
      subroutine phases()
         integer :: k
         associate (v => self%v, vn => self%vn, pers => self%pers, pen => self%pen, &
                    force => self%force)
            if (impact) then
               k = imp_c
               if (o%ph_open(k)) call observer_close_phase(o, k, t_prev, row_dot(m%con, k, vn))
               call observer_open_phase(o, k, t_prev + alpha_imp*h, v_imp)
               o%counters(C_EVENTS) = o%counters(C_EVENTS) + 1_i8
               if (.not. pers(k)) call observer_close_phase(o, k, t_prev + alpha_imp*h, &
                                                            row_dot(m%con, k, v), pen(k), force(k))
            end if
            do k = 1, nc
               if (o%ph_open(k) .and. .not. pers(k)) &
                  call observer_close_phase(o, k, t_prev, row_dot(m%con, k, vn), pen(k), force(k))
            end do
         end associate
      end subroutine phases
   end subroutine step
end module martello_newmark_lagrange
