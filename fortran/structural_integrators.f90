!> Fixed-step structural integrators for penalty scenes (PROBLEMS.md "Integrators", seed §4):
!>  - the generalized-α family, one Newton kernel for Newmark (any β, γ; α_m = α_f = 0),
!>    HHT-α (α_m = 0, α_f = −α) and Chung–Hulbert generalized-α (ρ∞). Residual with the
!>    forces interpolated between the old and new states (Hilber et al. 1977; Chung & Hulbert
!>    1993, eqs 3–5), consistent tangent, and a residual-plus-increment convergence test;
!>  - explicit central difference (velocity Verlet) with an extrapolated damping velocity
!>    v_n + h a_n and an a priori stability check against Δt_crit = 2/ω_max.
!> Every step is O(n·kd²): band assembly and solve, workspaces allocated once per run.
module martello_structural_integrators
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_bandwidth, SCHEME_PENALTY, scheme_name
   use martello_band_matrix
   use martello_assembly
   use martello_results
   use martello_stability, only: omega_max
   use martello_run_checks, only: check_run_settings, check_divergence
   use martello_integrator_settings
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: run_structural, generalized_alpha_coefficients

contains

   !> (α_m, α_f, β, γ) of the family member; α's weigh the old state.
   pure subroutine generalized_alpha_coefficients(s, am, af, beta, gamma)
      type(integrator_settings_t), intent(in) :: s
      real(dp), intent(out) :: am, af, beta, gamma
      select case (s%kind)
      case (INT_HHT)                 ! Hilber–Hughes–Taylor (1977)
         am = 0.0_dp; af = -s%alpha
         gamma = 0.5_dp - s%alpha; beta = 0.25_dp*(1.0_dp - s%alpha)**2
      case (INT_GENERALIZED_ALPHA)   ! Chung & Hulbert (1993), eq. 25
         am = (2.0_dp*s%rho_inf - 1.0_dp)/(s%rho_inf + 1.0_dp)
         af = s%rho_inf/(s%rho_inf + 1.0_dp)
         gamma = 0.5_dp - am + af; beta = 0.25_dp*(1.0_dp - am + af)**2
      case default                   ! Newmark (1959)
         am = 0.0_dp; af = 0.0_dp; beta = s%beta; gamma = s%gamma
      end select
   end subroutine generalized_alpha_coefficients

   !> Run a scene from t = 0 to t_end. stat < 0 on failure with r%message saying where/why;
   !> the results filled so far stay in r for diagnosis but are not a result.
   subroutine run_structural(m, s, r, stat)
      type(model_t), intent(inout) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat

      integer :: n, kd, j, nsteps, step, it, info
      real(dp), allocatable :: u(:), v(:), a(:), un(:), vn(:), an(:), fint(:), fint_n(:), &
                               fext(:), fext_n(:), res(:), du(:), work(:), mrow(:), ma(:)
      real(dp), allocatable :: man(:)
      integer, allocatable :: fixed_nodes(:)
      ! open contact phases: onset time, speed, running maxima
      real(dp), allocatable :: ph_t(:), ph_v(:), ph_pen(:), ph_f(:)
      logical, allocatable :: ph_open(:)
      type(mech_state_t) :: ms
      type(band_t) :: jac, mband, cjac
      real(dp) :: h, t, am, af, beta, gamma, cm, cv, fscale, uscale, rnorm, incr, &
                  e_kin, e_links, e_cont, e_links0, e_cont0, e0, w_ext, d_damp, d_links, &
                  ke_corr, e0_alg, &
                  d_contact, w_abs, wd, wl, wc, e_mech, mmax, fmag, fext_mag
      logical :: ok, converged, recording, tangent_valid
      !> steps between divergence checks on the mechanical energy (NaN is caught every step
      !> through the work increments)
      integer, parameter :: ENERGY_CHECK = 16

      stat = MARTELLO_OK
      n = m%n
      call check_run_settings(m, s, r, stat)
      if (stat /= MARTELLO_OK) return
      h = s%dt
      ! Whole steps of h until t_end is reached: the last recorded time is nsteps·h ≥ t_end
      ! (reported as t_reached), never a shortened step labelled t_end.
      nsteps = max(1, ceiling(s%t_end/h*(1.0_dp - 1.0e-12_dp)))
      kd = model_bandwidth(m)

      allocate (u(0:n), v(0:n), a(0:n), un(0:n), vn(0:n), an(0:n), fint(0:n), fint_n(0:n), &
                fext(0:n), fext_n(0:n), res(0:n), du(n), work(0:n), mrow(0:n), ma(0:n), man(0:n))
      allocate (ph_t(m%ncontact), ph_v(m%ncontact), ph_pen(m%ncontact), ph_f(m%ncontact), &
                ph_open(m%ncontact))
      ph_open = .false.
      fixed_nodes = pack([(j, j = 1, n)], m%fixed)
      call band_init(jac, n, kd)
      call band_init(mband, n, kd)
      call band_init(cjac, n, kd)
      tangent_valid = .false.

      ! initial state; M·1 carries gravity and ground-motion loads
      u(0) = 0.0_dp; v(0) = 0.0_dp
      u(1:n) = m%u0; v(1:n) = merge(0.0_dp, m%v0, m%fixed)
      work = 1.0_dp; work(0) = 0.0_dp
      call mass_times(m, work, mrow)
      call mech_init(m, ms, u, v)
      call internal_forces(m, ms, u, v, fint)
      call external_forces(m, mrow, 0.0_dp, fext)
      call initial_acceleration(ok)
      if (.not. ok) then
         call fail(MARTELLO_ERR_SINGULAR, 'the mass matrix is singular on the free nodes')
         return
      end if
      call mech_commit(m, ms, u)

      ! stability of the explicit scheme, before anything is written
      if (s%kind == INT_CENTRAL_DIFFERENCE) then
         call omega_max(m, r%omega_max, info)
         if (info /= 0 .and. s%check_stability) then
            write (r%message, '(a,i0,a)') 'central difference: the stability limit could not be computed'// &
               ' (LAPACK dsbgvx info = ', info, '): the mass matrix is not positive definite'
            stat = MARTELLO_ERR_SINGULAR
            return
         end if
         if (info == 0 .and. r%omega_max > 0.0_dp) r%dt_critical = 2.0_dp/r%omega_max
         if (s%check_stability .and. r%dt_critical > 0.0_dp .and. h > r%dt_critical) then
            write (r%message, '(a,es12.5,a,es12.5,a,es11.4,a)') 'central difference is unstable: dt = ', &
               h, ' s exceeds dt_crit = 2/omega_max = ', r%dt_critical, ' s (omega_max = ', &
               r%omega_max, ' rad/s, penalty stiffness included); reduce dt or use an implicit integrator'
            stat = MARTELLO_ERR_UNSTABLE
            return
         end if
      end if

      ! contacts already closed at t = 0 start a contact phase there (no approach to locate)
      do j = 1, m%ncontact
         if (ms%con_on(j)) then
            ph_open(j) = .true.; ph_t(j) = 0.0_dp
            ph_v(j) = v(m%con_a(j)) - v(m%con_b(j)); ph_pen(j) = 0.0_dp; ph_f(j) = 0.0_dp
            r%impacts(j) = r%impacts(j) + 1
         end if
      end do

      call generalized_alpha_coefficients(s, am, af, beta, gamma)
      cm = (1.0_dp - am)/(beta*h*h)
      mmax = max(maxval(m%mass), tiny(1.0_dp))
      cv = gamma/(beta*h)
      e_kin = kinetic_energy(m, v, ma); ke_corr = kinetic_correction()
      call recoverable_energy(m, ms, u, e_links, e_cont)
      e_links0 = e_links; e_cont0 = e_cont
      e0 = e_kin + e_links + e_cont
      e0_alg = e0 - ke_corr
      w_ext = 0.0_dp; d_damp = 0.0_dp; d_links = 0.0_dp; d_contact = 0.0_dp; w_abs = 0.0_dp
      t = 0.0_dp
      call results_track(r, t, u(1:n), v(1:n), a(1:n), ms%con_pen, ms%con_f, ms%link_f, ms%link_u)
      call record()

      do step = 1, nsteps
         un = u; vn = v; an = a; fint_n = fint; fext_n = fext
         call mass_times(m, an, man)
         t = step*h
         call external_forces(m, mrow, t, fext)
         fext_mag = maxval(abs(fext))

         if (s%kind == INT_CENTRAL_DIFFERENCE) then
            call central_difference_step(ok)
            if (.not. ok) then
               call fail(MARTELLO_ERR_SINGULAR, 'the mass matrix is singular on the free nodes')
               return
            end if
         else
            call newton_step(converged)
            if (.not. converged) return
         end if
         r%counters(C_STEPS) = r%counters(C_STEPS) + 1_i8
         ! energy balance: trapezoidal work of every force over the step (elements in commit)
         call mech_commit(m, ms, u, wd, wl, wc)
         d_damp = d_damp + wd; d_links = d_links + wl; d_contact = d_contact + wc
         wd = external_work(m, fext_n, fext, un, u)
         w_ext = w_ext + wd; w_abs = w_abs + abs(wd)
         call track_events()
         ! the previous state is the integrator's own (un, vn, an): no copy in the results
         call results_track(r, t, u(1:n), v(1:n), a(1:n), ms%con_pen, ms%con_f, ms%link_f, ms%link_u, &
                            un(1:n), vn(1:n), an(1:n))
         recording = mod(step, s%every) == 0 .or. step == nsteps
         ! kinetic and recoverable energy (two passes over the model) only where needed: at
         ! recorded steps and every ENERGY_CHECK steps for the divergence test
         if (.not. (recording .or. mod(step, ENERGY_CHECK) == 0 .or. &
                    .not. ieee_is_finite(wd + d_links + d_contact + d_damp))) cycle
         e_kin = kinetic_energy(m, v, ma); ke_corr = kinetic_correction()
         call recoverable_energy(m, ms, u, e_links, e_cont)
         r%energy_balance_max = max(r%energy_balance_max, abs(e0_alg + w_ext - (e_kin - ke_corr) - e_links - e_cont &
                                                              - d_damp - d_links - d_contact + &
                                                              (e_links - e_links0) + (e_cont - e_cont0)))
         if (recording) call record()

         ! divergence: NaN, or mechanical energy far beyond what was put in
         e_mech = e_kin + e_links + e_cont
         call check_divergence(s, t, e_mech, e0, w_abs, u, v, &
                               'the step is past the stability limit', r, stat)
         if (stat /= MARTELLO_OK) return
      end do
      call close_open_phases()
      r%t_end_reached = t

   contains

      subroutine fail(code, msg)
         integer, intent(in) :: code
         character(len=*), intent(in) :: msg
         stat = code
         write (r%message, '(a,a,es12.5,a)') msg, ' (t = ', t, ' s)'
         r%t_end_reached = t
      end subroutine fail

      !> Velocity Verlet conserves ½vᵀMv − (h²/8)aᵀMa exactly against trapezoidal work
      !> (the a-terms of ΔKE telescope), so the central-difference balance uses it and is an
      !> identity to round-off, like average acceleration's. 0 for the implicit family.
      real(dp) function kinetic_correction()
         kinetic_correction = 0.0_dp
         if (s%kind /= INT_CENTRAL_DIFFERENCE) return
         call mass_times(m, a, ma)
         kinetic_correction = 0.125_dp*h*h*dot_product(a(1:n), ma(1:n))
      end function kinetic_correction


      !> M a = fext − fint on the free nodes (fixed nodes: a = 0).
      subroutine solve_mass(rhs, ok)
         real(dp), intent(inout) :: rhs(0:)
         logical, intent(out) :: ok
         integer :: i
         call band_zero(mband)
         call assemble_mass(m, 1.0_dp, mband)
         do i = 1, n
            if (m%fixed(i)) then
               call pin_row(mband, i); rhs(i) = 0.0_dp
            end if
         end do
         call band_solve(mband, rhs(1:n), ok)
         rhs(0) = 0.0_dp
         r%counters(C_FACTORIZATIONS) = r%counters(C_FACTORIZATIONS) + 1_i8
      end subroutine solve_mass

      subroutine initial_acceleration(ok)
         logical, intent(out) :: ok
         a = fext - fint
         call solve_mass(a, ok)
      end subroutine initial_acceleration

      !> Replace row and column i by the identity (a fixed DOF: Δu_i = 0).
      subroutine pin_row(b, i)
         type(band_t), intent(inout) :: b
         integer, intent(in) :: i
         integer :: jj, rr
         rr = 2*b%kd + 1
         do jj = max(1, i - b%kd), min(n, i + b%kd)
            b%ab(rr + i - jj, jj) = 0.0_dp      ! row i
            b%ab(rr + jj - i, i) = 0.0_dp       ! column i
         end do
         b%ab(rr, i) = 1.0_dp
      end subroutine pin_row

      !> Newmark relations for a trial u: a(u), v(u).
      subroutine kinematics()
         integer :: i, k
         a(1:n) = (u(1:n) - un(1:n) - h*vn(1:n))/(beta*h*h) - (0.5_dp - beta)/beta*an(1:n)
         v(1:n) = vn(1:n) + h*((1.0_dp - gamma)*an(1:n) + gamma*a(1:n))
         do k = 1, size(fixed_nodes)
            i = fixed_nodes(k)
            u(i) = un(i); v(i) = 0.0_dp; a(i) = 0.0_dp
         end do
      end subroutine kinematics

      !> Newton on the step. A law whose force jumps at δ = 0 (Kelvin: cδ̇ at first touch and
      !> at separation) can leave the step without any root: the iterates then flip the
      !> contact on and off. Chatter rule: a contact that flips in three iterations of one
      !> step is held open (F = 0) for this step and Newton restarts; the onset is thus
      !> delayed, or the separation advanced, by at most one step (O(h), counted in the
      !> contact_chatter_resolutions counter).
      subroutine newton_step(converged)
         logical, intent(out) :: converged
         integer :: restart
         integer :: flips(m%ncontact)
         logical :: was_on(m%ncontact)
         converged = .false.
         do restart = 0, 1
            flips = 0; was_on = ms%con_on
            if (restart == 0 .and. tangent_valid) then
               ! First iterate from the committed state with the tangent assembled there at
               ! the end of the last step: no element loop is needed for it, so a step whose
               ! laws stay on one branch costs a single evaluation.
               call linearised_first_iterate(ok)
               if (.not. ok) then
                  call fail(MARTELLO_ERR_SINGULAR, 'singular effective stiffness in the Newton step')
                  return
               end if
               call newton_iterations(converged, flips, was_on, 1)
            else
               ! predictor: constant acceleration
               u(1:n) = un(1:n) + h*vn(1:n) + 0.5_dp*h*h*an(1:n)
               call newton_iterations(converged, flips, was_on, 0)
            end if
            tangent_valid = converged .and. kd <= 1
            if (converged .or. stat /= MARTELLO_OK) return
            if (.not. any(flips >= 3)) exit
            ms%forced_off = ms%forced_off .or. flips >= 3
            r%counters(C_CHATTER) = r%counters(C_CHATTER) + 1_i8
         end do
         if (.not. converged) then
            write (r%message, '(a,es12.5,a,i0,a,es9.2,a,es9.2,a)') 'Newton did not converge at t = ', t, &
               ' s after ', s%max_newton, ' iterations (residual ', rnorm/fscale, &
               ' of the force scale, tolerance ', s%tol_residual, '); reduce dt'
            stat = MARTELLO_ERR_NOT_CONVERGED; r%t_end_reached = t
         end if
      end subroutine newton_step

      !> u = u_n + Δu with J Δu = −r(u_n), where r(u_n) uses the committed internal force and
      !> the damping tangent C of the last evaluation for the velocity change (exact for
      !> linear dampers). J is intact: the kd ≤ 1 solve works on copies.
      subroutine linearised_first_iterate(ok)
         logical, intent(out) :: ok
         u = un
         call kinematics()
         work(1:n) = v(1:n) - vn(1:n)
         call band_matvec(cjac, work(1:n), res(1:n))   ! C_t Δv
         res(0) = 0.0_dp
         call mass_times(m, a, ma)
         res = (1.0_dp - am)*ma + am*man + (1.0_dp - af)*(fint_n + res) + af*fint_n &
               - (1.0_dp - af)*fext - af*fext_n
         res(fixed_nodes) = 0.0_dp
         du = -res(1:n)
         call band_solve(jac, du, ok)
         r%counters(C_FACTORIZATIONS) = r%counters(C_FACTORIZATIONS) + 1_i8
         r%counters(C_NEWTON) = r%counters(C_NEWTON) + 1_i8
         u(1:n) = un(1:n) + du
      end subroutine linearised_first_iterate

      !> Residual of the step at the current u, the effective stiffness
      !> J = c_m M + (1−α_f)(K_t + c_v C_t) with fixed rows pinned, min_i J_ii, and the
      !> damping tangent C_t (kept for the next step's first iterate).
      subroutine evaluate(want_jac)
         logical, intent(in) :: want_jac
         integer :: i
         call kinematics()
         if (want_jac) then
            jac%ab = 0.0_dp; cjac%ab = 0.0_dp
            call internal_forces(m, ms, u, v, fint, jac%ab, 1.0_dp - af, (1.0_dp - af)*cv, cjac%ab)
            call assemble_mass(m, cm, jac)
            r%counters(C_JACOBIANS) = r%counters(C_JACOBIANS) + 1_i8
            do i = 1, size(fixed_nodes)
               call pin_row(jac, fixed_nodes(i))
            end do
         else
            call internal_forces(m, ms, u, v, fint)
         end if
         r%counters(C_RESIDUALS) = r%counters(C_RESIDUALS) + 1_i8
         call mass_times(m, a, ma)
         ! residual and the magnitudes for the convergence test, in one pass
         rnorm = 0.0_dp; fmag = fext_mag
         do i = 1, n
            res(i) = (1.0_dp - am)*ma(i) + am*man(i) + (1.0_dp - af)*fint(i) + af*fint_n(i) &
                     - (1.0_dp - af)*fext(i) - af*fext_n(i)
            fmag = max(fmag, abs(fint(i)), abs(ma(i)))
         end do
         res(0) = 0.0_dp
         res(fixed_nodes) = 0.0_dp
         rnorm = maxval(abs(res(1:n)))
         ! the next Newton increment, estimated node by node as |r_i|/J_ii (exact for a
         ! diagonal J, within a factor 2 for the diagonally dominant J of a chain): a light
         ! node next to a heavy one is judged by its own stiffness, not the global minimum
         incr = 0.0_dp
         if (want_jac) then
            do i = 1, n
               if (res(i) /= 0.0_dp) incr = max(incr, abs(res(i))/abs(jac%ab(2*kd + 1, i)))
            end do
         end if
      end subroutine evaluate

      subroutine newton_iterations(converged, flips, was_on, first)
         logical, intent(out) :: converged
         integer, intent(inout) :: flips(:)
         logical, intent(inout) :: was_on(:)
         integer, intent(in) :: first
         integer :: i
         logical :: on
         converged = .false.
         uscale = tiny(1.0_dp)
         do i = 1, n
            uscale = max(uscale, abs(un(i)), h*abs(vn(i)), h*h*abs(an(i)))
         end do
         do it = first, s%max_newton
            ! J is assembled at every iterate: the converged one serves the next step
            call evaluate(.true.)
            do i = 1, m%ncontact
               on = ms%con_pen_trial(i) > 0.0_dp .and. .not. ms%forced_off(i)
               if (on .neqv. was_on(i)) flips(i) = flips(i) + 1
               was_on(i) = on
            end do
            ! The inertia term cm·M·u is evaluated with rounding error ~ε·cm·m·|u|, which can
            ! exceed the physical forces by far (small h, free flight): it floors the scale.
            fscale = max(fmag, 64.0_dp*epsilon(1.0_dp)/s%tol_residual*cm*mmax*uscale, tiny(1.0_dp))
            ! residual test, and the increment the next iteration would make, both small
            if (it == 1) uscale = max(uscale, maxval(abs(u)))
            if (it > 0 .and. rnorm <= s%tol_residual*fscale .and. &
                incr <= s%tol_increment*uscale) then
               converged = .true.
               exit
            end if
            if (it == s%max_newton) exit
            du = -res(1:n)
            call band_solve(jac, du, ok)
            r%counters(C_FACTORIZATIONS) = r%counters(C_FACTORIZATIONS) + 1_i8
            r%counters(C_NEWTON) = r%counters(C_NEWTON) + 1_i8
            if (.not. ok) then
               call fail(MARTELLO_ERR_SINGULAR, 'singular effective stiffness in the Newton step')
               return
            end if
            if (it >= 2) then
               call line_search(rnorm)
            else
               u(1:n) = u(1:n) + du
            end if
         end do
      end subroutine newton_iterations

      !> Backtracking on ‖r‖∞ once plain Newton has taken two steps without converging: laws
      !> whose tangent is unbounded at first touch (Jankowski: ∂F/∂δ ~ δ^{−3/4}) or that switch
      !> branch inside a step make full steps overshoot; halving restores a decrease.
      subroutine line_search(r0)
         real(dp), intent(in) :: r0
         real(dp) :: lam, rtrial
         integer :: k
         work(1:n) = u(1:n)
         lam = 1.0_dp
         do k = 1, 12
            u(1:n) = work(1:n) + lam*du
            call kinematics()
            call internal_forces(m, ms, u, v, fint)
            call mass_times(m, a, ma)
            res = (1.0_dp - am)*ma + am*man + (1.0_dp - af)*fint + af*fint_n &
                  - (1.0_dp - af)*fext - af*fext_n
            res(fixed_nodes) = 0.0_dp
            r%counters(C_RESIDUALS) = r%counters(C_RESIDUALS) + 1_i8
            rtrial = maxval(abs(res(1:n)))
            if (rtrial < r0) return
            lam = 0.5_dp*lam
         end do
      end subroutine line_search

      !> Velocity Verlet. Velocity-dependent forces (dampers, contact rates) see the explicit
      !> estimate v* = v_n + h a_n of v_{n+1}: O(h²) accurate, so the scheme stays second
      !> order with damping (a lagged v_{n+1/2} would make it first order).
      subroutine central_difference_step(ok)
         logical, intent(out) :: ok
         u = un + h*(vn + 0.5_dp*h*an)
         work = vn + h*an
         u(fixed_nodes) = un(fixed_nodes); work(fixed_nodes) = 0.0_dp
         call internal_forces(m, ms, u, work, fint)
         r%counters(C_RESIDUALS) = r%counters(C_RESIDUALS) + 1_i8
         a = fext - fint
         call solve_mass(a, ok)
         v = vn + 0.5_dp*h*(an + a)
         v(fixed_nodes) = 0.0_dp
      end subroutine central_difference_step

      !> Contact phases: onset and separation times located on the free side of the step by
      !> the quadratic δ + δ̇τ + ½δ̈τ² = 0 (O(h³) in time), speeds extrapolated likewise.
      subroutine track_events()
         integer :: c, ia, ib
         real(dp) :: d0, r0, q0, tau
         do c = 1, m%ncontact
            ia = m%con_a(c); ib = m%con_b(c)
            if (.not. ph_open(c) .and. ms%con_on(c)) then
               d0 = un(ia) - un(ib) - m%con_gap(c); r0 = vn(ia) - vn(ib); q0 = an(ia) - an(ib)
               tau = free_side_crossing(d0, r0, q0, 0.0_dp, h)
               ph_open(c) = .true.
               ph_t(c) = t - h + tau; ph_v(c) = r0 + q0*tau
               ph_pen(c) = 0.0_dp; ph_f(c) = 0.0_dp
               r%impacts(c) = r%impacts(c) + 1
               r%counters(C_EVENTS) = r%counters(C_EVENTS) + 1_i8
            end if
            if (ph_open(c)) then
               ph_pen(c) = max(ph_pen(c), ms%con_pen(c)); ph_f(c) = max(ph_f(c), ms%con_f(c))
               if (.not. ms%con_on(c)) then
                  d0 = u(ia) - u(ib) - m%con_gap(c); r0 = v(ia) - v(ib); q0 = a(ia) - a(ib)
                  tau = free_side_crossing(d0, r0, q0, -h, 0.0_dp)
                  call results_add_event(r, c, [ph_t(c), t + tau, ph_v(c), r0 + q0*tau, &
                                                ph_pen(c), ph_f(c)])
                  ph_open(c) = .false.
               end if
            end if
         end do
      end subroutine track_events

      subroutine close_open_phases()
         integer :: c
         do c = 1, m%ncontact
            if (ph_open(c)) call results_add_event(r, c, [ph_t(c), -1.0_dp, ph_v(c), 0.0_dp, &
                                                          ph_pen(c), ph_f(c)])
         end do
      end subroutine close_open_phases

      !> Energy terms: W are trapezoidal works since t = 0, E recoverable energies; the
      !> dissipation of links (plasticity) and contacts is their work minus the change of
      !> their recoverable energy, so the balance is the work–energy identity
      !> KE0 + W_ext − KE − W_damp − W_links − W_contact (≈ 0 to the integrator's accuracy).
      subroutine record()
         real(dp) :: e(NENERGY)
         e = energy_terms(e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, d_links, &
                          d_contact, 0.0_dp, ke_corr, e0 - e0_alg)
         r%energy = e
         r%energy_balance_max = max(r%energy_balance_max, abs(e(E_BALANCE)))
         call results_record(r, t, u(1:n), v(1:n), a(1:n), ms%con_pen, ms%con_f, e, ms%link_f, ms%link_u)
      end subroutine record

   end subroutine run_structural
end module martello_structural_integrators
