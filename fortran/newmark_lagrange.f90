!> The seed's Newmark–Lagrange scheme (Papadrakakis et al. 1991; seed eq. 48; PROBLEMS.md
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
!>                                               PROBLEMS.md's "γ(1 − α)/β − 1 = e").
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
module martello_newmark_lagrange
   use martello_kinds, only: dp, i8
   use martello_status
   use martello_model, only: model_t, model_bandwidth, rigid_contact_sides
   use martello_band_matrix, only: band_t, band_init
   use martello_assembly, only: mech_state_t, mech_init, internal_forces, external_forces, &
      mech_commit, recoverable_energy, mass_times, external_work, kinetic_energy
   use martello_results
   use martello_run_checks, only: check_run_settings, check_divergence
   use martello_integrator_settings, only: integrator_settings_t, integrator_name, scheme_supported
   use martello_linalg, only: solve_symmetric_indefinite
   use martello_impulse, only: impulse_accumulation
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: run_newmark_lagrange, NL_MAX_NODES

   !> Dense KKT systems: refuse scenes beyond this size (the scheme is meant for P2 and P5).
   integer, parameter :: NL_MAX_NODES = 500

contains

   subroutine run_newmark_lagrange(m, s, r, stat)
      type(model_t), intent(inout) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat

      integer :: n, kd, nc, nsteps, step, i, c, ci, attempt
      real(dp), allocatable :: u(:), v(:), a(:), un(:), vn(:), an(:), fint(:), fint_n(:), &
                               fext(:), fext_n(:), mrow(:), ma(:), work(:), mdense(:, :)
      real(dp), allocatable :: e_con(:), lam(:), lam_n(:), pen(:), force(:), mstar(:)
      integer, allocatable :: sa(:), sb(:), fixed_nodes(:)
      logical, allocatable :: rigid(:), pers(:), active(:), movable(:), ph_open(:)
      real(dp), allocatable :: ph_t(:), ph_v(:), ph_pen(:), ph_f(:)
      type(mech_state_t) :: ms
      type(band_t) :: kband, cband
      real(dp) :: h, t, t_prev, beta, gamma, e_kin, e_links, e_cont, e_links0, e_cont0, e0, &
                  w_ext, d_damp, d_links, d_contact, d_impact, w_abs, wdl, wll, wcl, e_mech, dw, &
                  alpha_imp, v_imp, e_eff, rr, d0, dd0, ddd0, tau, best_alpha, lam_tol, t_inf
      logical :: converged, recording, impact, released, zeno
      integer :: imp_c
      integer, parameter :: ENERGY_CHECK = 16

      stat = MARTELLO_OK
      n = m%n
      nc = m%ncontact
      t = 0.0_dp
      call check_scene(stat)
      if (stat /= MARTELLO_OK) return
      h = s%dt
      ! whole steps until t_end is reached; the last time is nsteps·h (reported as t_reached)
      nsteps = max(1, ceiling(s%t_end/h*(1.0_dp - 1.0e-12_dp)))
      kd = model_bandwidth(m)

      allocate (u(0:n), v(0:n), a(0:n), un(0:n), vn(0:n), an(0:n), fint(0:n), fint_n(0:n), &
                fext(0:n), fext_n(0:n), mrow(0:n), ma(0:n), work(0:n), mdense(n, n))
      allocate (e_con(nc), lam(nc), lam_n(nc), pen(nc), force(nc), mstar(nc), sa(nc), sb(nc), &
                rigid(nc), pers(nc), active(nc), movable(nc), ph_open(nc), ph_t(nc), ph_v(nc), &
                ph_pen(nc), ph_f(nc))
      fixed_nodes = pack([(i, i = 1, n)], m%fixed)
      call band_init(kband, n, kd)
      call band_init(cband, n, kd)
      ph_open = .false.; pers = .false.; lam = 0.0_dp; lam_n = 0.0_dp

      ! dense mass matrix (lumped diagonal and consistent couplings), columns by M e_i
      do i = 1, n
         work = 0.0_dp; work(i) = 1.0_dp
         call mass_times(m, work, ma)
         mdense(:, i) = ma(1:n)
      end do
      call rigid_contact_sides(m, rigid, e_con, sa, sb, movable)
      do c = 1, nc
         ! effective mass of the contact, 1/(B M⁻¹ Bᵀ), for the impact energy loss
         mstar(c) = 0.0_dp
         if (movable(c)) mstar(c) = effective_mass(c)
      end do

      u(0) = 0.0_dp; v(0) = 0.0_dp
      u(1:n) = m%u0; v(1:n) = merge(0.0_dp, m%v0, m%fixed)
      work = 1.0_dp; work(0) = 0.0_dp
      call mass_times(m, work, mrow)
      call mech_init(m, ms, u, v)
      call internal_forces(m, ms, u, v, fint)
      call mech_commit(m, ms, u)
      call external_forces(m, mrow, 0.0_dp, fext)
      call equilibrium_acceleration(converged)
      if (.not. converged) return

      e_kin = kinetic_energy(m, v, ma)
      call recoverable_energy(m, ms, u, e_links, e_cont)
      e_links0 = e_links; e_cont0 = e_cont
      e0 = e_kin + e_links + e_cont
      w_ext = 0.0_dp; d_damp = 0.0_dp; d_links = 0.0_dp; d_contact = 0.0_dp; d_impact = 0.0_dp
      w_abs = 0.0_dp
      call contact_state()
      call results_track(r, t, u(1:n), v(1:n), a(1:n), pen, force, ms%link_f, ms%link_u)
      call record()

      do step = 1, nsteps
         un = u; vn = v; an = a; fint_n = fint; fext_n = fext; lam_n = lam
         t_prev = t
         t = step*h
         call external_forces(m, mrow, t, fext)

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
            r%counters(C_REJECTED) = r%counters(C_REJECTED) + 1_i8
         end do

         ! 2. a free contact that the trial closed: the earliest one sets (β, γ) for the step
         impact = .false.; imp_c = 0; best_alpha = huge(1.0_dp)
         do c = 1, nc
            if (.not. movable(c) .or. pers(c)) cycle
            if (u(m%con_a(c)) - u(m%con_b(c)) - m%con_gap(c) > closed_tol(c)) then
               d0 = un(m%con_a(c)) - un(m%con_b(c)) - m%con_gap(c)
               dd0 = vn(m%con_a(c)) - vn(m%con_b(c))
               ddd0 = an(m%con_a(c)) - an(m%con_b(c))
               tau = 0.0_dp
               if (d0 < 0.0_dp) tau = free_side_crossing(d0, dd0, ddd0, 0.0_dp, h)
               if (tau/h < best_alpha) then
                  best_alpha = tau/h; imp_c = c
               end if
            end if
         end do
         if (imp_c > 0) then
            impact = .true.
            r%counters(C_REJECTED) = r%counters(C_REJECTED) + 1_i8
            c = imp_c
            alpha_imp = best_alpha
            d0 = un(m%con_a(c)) - un(m%con_b(c)) - m%con_gap(c)
            dd0 = vn(m%con_a(c)) - vn(m%con_b(c))
            ddd0 = an(m%con_a(c)) - an(m%con_b(c))
            v_imp = dd0 + alpha_imp*h*ddd0
            e_eff = e_con(c)
            ! Zeno: the next rebound flight under the pressing acceleration δ̈_n is shorter than
            ! a step (one impact a step is what the tuned (β, γ) resolve)
            call impulse_accumulation(e_eff, e_eff*max(v_imp, 0.0_dp), ddd0, t_prev + alpha_imp*h, &
                                      h, 0.0_dp, zeno, t_inf)
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
                   u(m%con_a(ci)) - u(m%con_b(ci)) - m%con_gap(ci) > closed_tol(ci)) active(ci) = .true.
            end do
            call newmark_solve(beta, gamma, converged)
            if (.not. converged) return
            if (e_eff == 0.0_dp) pers(c) = .true.
            do ci = 1, nc      ! other contacts closed in the same step: held from now on
               if (ci /= c .and. active(ci) .and. .not. pers(ci)) pers(ci) = .true.
            end do
            d_impact = d_impact + 0.5_dp*mstar(c)*(v_imp**2 - (v(m%con_a(c)) - v(m%con_b(c)))**2)
         end if

         r%counters(C_STEPS) = r%counters(C_STEPS) + 1_i8
         call mech_commit(m, ms, u, wdl, wll, wcl)
         d_damp = d_damp + wdl; d_links = d_links + wll; d_contact = d_contact + wcl
         dw = external_work(m, fext_n, fext, un, u)
         w_ext = w_ext + dw; w_abs = w_abs + abs(dw)
         call contact_state()
         call track_events()
         ! the impulsive acceleration of an impact step must not enter the next predictor
         if (impact) then
            call equilibrium_acceleration(converged)
            if (.not. converged) return
         end if
         call results_track(r, t, u(1:n), v(1:n), a(1:n), pen, force, ms%link_f, ms%link_u)
         recording = mod(step, s%every) == 0 .or. step == nsteps
         if (.not. (recording .or. mod(step, ENERGY_CHECK) == 0 .or. &
                    .not. ieee_is_finite(dw + d_impact + d_links + d_damp))) cycle
         e_kin = kinetic_energy(m, v, ma)
         call recoverable_energy(m, ms, u, e_links, e_cont)
         if (recording) call record()
         e_mech = e_kin + e_links + e_cont
         call check_divergence(s, t, e_mech, e0, w_abs, u, v, 'reduce dt', r, stat)
         if (stat /= MARTELLO_OK) return
      end do
      call close_open_phases()
      r%t_end_reached = t

   contains

      subroutine check_scene(st)
         integer, intent(out) :: st
         character(len=16) :: num
         call check_run_settings(m, s, r, st)
         if (st /= MARTELLO_OK) return
         if (m%n > NL_MAX_NODES) then
            write (num, '(i0)') NL_MAX_NODES
            st = MARTELLO_ERR_UNSUPPORTED
            r%message = 'newmark-lagrange solves dense KKT systems and is meant for small problems'// &
               ' (P2, P5): at most '//trim(num)//' nodes; use moreau-jean for chains'
            return
         end if
      end subroutine check_scene

      !> A contact counts as closed by the trial beyond the rounding of its gap: the constraint
      !> of an impact step leaves δ_{n+1} = 0 only to a few ulps of the coordinates.
      real(dp) function closed_tol(cc)
         integer, intent(in) :: cc
         closed_tol = 8.0_dp*epsilon(1.0_dp)*(abs(u(m%con_a(cc))) + abs(u(m%con_b(cc))) + abs(m%con_gap(cc)))
      end function closed_tol


      !> 1/(B M⁻¹ Bᵀ) of contact cc (M restricted to the free nodes).
      real(dp) function effective_mass(cc)
         integer, intent(in) :: cc
         real(dp) :: mm(n, n), x(n), rc
         integer :: st
         character(len=256) :: msg
         mm = mdense
         x = 0.0_dp
         if (sa(cc) > 0) x(sa(cc)) = -1.0_dp
         if (sb(cc) > 0) x(sb(cc)) = 1.0_dp
         do st = 1, size(fixed_nodes)
            mm(fixed_nodes(st), :) = 0.0_dp; mm(:, fixed_nodes(st)) = 0.0_dp
            mm(fixed_nodes(st), fixed_nodes(st)) = 1.0_dp
         end do
         call solve_symmetric_indefinite(mm, x, rc, st, msg)
         effective_mass = 0.0_dp
         if (st /= MARTELLO_OK) return
         rc = 0.0_dp
         if (sb(cc) > 0) rc = rc + x(sb(cc))
         if (sa(cc) > 0) rc = rc - x(sa(cc))
         if (rc > 0.0_dp) effective_mass = 1.0_dp/rc
      end function effective_mass

      !> Newmark relations for the current u with (bt, gm).
      subroutine kinematics(bt, gm)
         real(dp), intent(in) :: bt, gm
         integer :: k
         a(1:n) = (u(1:n) - un(1:n) - h*vn(1:n))/(bt*h*h) - (0.5_dp - bt)/bt*an(1:n)
         v(1:n) = vn(1:n) + h*((1.0_dp - gm)*an(1:n) + gm*a(1:n))
         do k = 1, size(fixed_nodes)
            u(fixed_nodes(k)) = un(fixed_nodes(k)); v(fixed_nodes(k)) = 0.0_dp
            a(fixed_nodes(k)) = 0.0_dp
         end do
      end subroutine kinematics

      !> Newton on the constrained Newmark step: unknowns u_{n+1} and the multipliers λ of
      !> the active contacts; KKT matrix [J −Bᵀ; −B 0], J = M/(βh²) + γ/(βh) C + K.
      subroutine newmark_solve(bt, gm, ok)
         real(dp), intent(in) :: bt, gm
         logical, intent(out) :: ok
         integer :: it, na, j, k, row, col, st, idx(nc)
         real(dp), allocatable :: kkt(:, :), rhs(:)
         real(dp) :: rnorm, cnorm, fscale, uscale, rc
         character(len=256) :: msg
         na = 0
         do j = 1, nc
            if (active(j)) then
               na = na + 1; idx(na) = j
            end if
         end do
         allocate (kkt(n + na, n + na), rhs(n + na))
         lam = 0.0_dp
         u(1:n) = un(1:n) + h*vn(1:n) + 0.5_dp*h*h*an(1:n)
         uscale = tiny(1.0_dp)
         do k = 1, n
            uscale = max(uscale, abs(un(k)), h*abs(vn(k)), h*h*abs(an(k)))
         end do
         ok = .false.
         do it = 0, s%max_newton
            call kinematics(bt, gm)
            kband%ab = 0.0_dp; cband%ab = 0.0_dp
            call internal_forces(m, ms, u, v, fint, kband%ab, 1.0_dp, 0.0_dp, cband%ab)
            r%counters(C_RESIDUALS) = r%counters(C_RESIDUALS) + 1_i8
            call mass_times(m, a, ma)
            rhs = 0.0_dp
            rhs(1:n) = ma(1:n) + fint(1:n) - fext(1:n)
            do j = 1, na
               k = idx(j)
               if (sa(k) > 0) rhs(sa(k)) = rhs(sa(k)) + lam(k)
               if (sb(k) > 0) rhs(sb(k)) = rhs(sb(k)) - lam(k)
               rhs(n + j) = u(m%con_a(k)) - u(m%con_b(k)) - m%con_gap(k)
            end do
            rhs(fixed_nodes) = 0.0_dp
            rnorm = maxval(abs(rhs(1:n)))
            cnorm = 0.0_dp
            if (na > 0) cnorm = maxval(abs(rhs(n + 1:n + na)))
            fscale = max(maxval(abs(fext(1:n))), maxval(abs(fint(1:n))), maxval(abs(ma(1:n))), &
                         maxval(abs(lam)), tiny(1.0_dp))
            ! the inertia term M u/(βh²) is evaluated with rounding ~ε·m|u|/(βh²)
            fscale = max(fscale, 64.0_dp*epsilon(1.0_dp)/s%tol_residual*maxval(m%mass)*uscale/(bt*h*h))
            if (it > 0 .and. rnorm <= s%tol_residual*fscale .and. &
                cnorm <= max(s%tol_increment*max(uscale, maxval(abs(u))), 16.0_dp*epsilon(1.0_dp)*maxval(abs(u)))) then
               ok = .true.
               exit
            end if
            if (it == s%max_newton) exit
            ! KKT matrix
            kkt = 0.0_dp
            kkt(1:n, 1:n) = mdense/(bt*h*h)
            do col = 1, n
               do row = max(1, col - kd), min(n, col + kd)
                  kkt(row, col) = kkt(row, col) + kband%ab(2*kd + 1 + row - col, col) + &
                                  gm/(bt*h)*cband%ab(2*kd + 1 + row - col, col)
               end do
            end do
            do j = 1, na
               k = idx(j)
               if (sa(k) > 0) then
                  kkt(sa(k), n + j) = 1.0_dp; kkt(n + j, sa(k)) = 1.0_dp
               end if
               if (sb(k) > 0) then
                  kkt(sb(k), n + j) = -1.0_dp; kkt(n + j, sb(k)) = -1.0_dp
               end if
            end do
            do j = 1, size(fixed_nodes)
               kkt(fixed_nodes(j), :) = 0.0_dp; kkt(:, fixed_nodes(j)) = 0.0_dp
               kkt(fixed_nodes(j), fixed_nodes(j)) = 1.0_dp
            end do
            rhs = -rhs
            call solve_symmetric_indefinite(kkt, rhs, rc, st, msg)
            r%counters(C_FACTORIZATIONS) = r%counters(C_FACTORIZATIONS) + 1_i8
            r%counters(C_NEWTON) = r%counters(C_NEWTON) + 1_i8
            if (st /= MARTELLO_OK) then
               stat = st
               write (r%message, '(a,es12.5,a)') 'Newmark-Lagrange: singular KKT system at t = ', t, &
                  ' s ('//trim(msg)//')'
               r%t_end_reached = t_prev
               return
            end if
            u(1:n) = u(1:n) + rhs(1:n)
            do j = 1, na
               lam(idx(j)) = lam(idx(j)) + rhs(n + j)
            end do
         end do
         if (.not. ok) then
            write (r%message, '(a,es12.5,a,i0,a)') 'Newmark-Lagrange: Newton did not converge at t = ', &
               t, ' s after ', s%max_newton, ' iterations; reduce dt'
            stat = MARTELLO_ERR_NOT_CONVERGED; r%t_end_reached = t_prev
         end if
      end subroutine newmark_solve

      !> a from M a = f_ext − fint + Bᵀλ with B a = 0 on the persistent contacts (their λ the
      !> contact forces of the state).
      subroutine equilibrium_acceleration(ok)
         logical, intent(out) :: ok
         integer :: na, j, k, st, idx(nc)
         real(dp), allocatable :: kkt(:, :), rhs(:)
         real(dp) :: rc
         character(len=256) :: msg
         na = 0
         do j = 1, nc
            if (pers(j) .and. movable(j)) then
               na = na + 1; idx(na) = j
            end if
         end do
         allocate (kkt(n + na, n + na), rhs(n + na))
         kkt = 0.0_dp
         kkt(1:n, 1:n) = mdense
         rhs = 0.0_dp
         rhs(1:n) = fext(1:n) - fint(1:n)
         do j = 1, na
            k = idx(j)
            if (sa(k) > 0) then
               kkt(sa(k), n + j) = 1.0_dp; kkt(n + j, sa(k)) = 1.0_dp
            end if
            if (sb(k) > 0) then
               kkt(sb(k), n + j) = -1.0_dp; kkt(n + j, sb(k)) = -1.0_dp
            end if
         end do
         do j = 1, size(fixed_nodes)
            kkt(fixed_nodes(j), :) = 0.0_dp; kkt(:, fixed_nodes(j)) = 0.0_dp
            kkt(fixed_nodes(j), fixed_nodes(j)) = 1.0_dp
            rhs(fixed_nodes(j)) = 0.0_dp
         end do
         call solve_symmetric_indefinite(kkt, rhs, rc, st, msg)
         r%counters(C_FACTORIZATIONS) = r%counters(C_FACTORIZATIONS) + 1_i8
         ok = st == MARTELLO_OK
         if (.not. ok) then
            stat = st
            r%message = 'Newmark-Lagrange: the mass matrix with the persistent contacts is singular ('// &
               trim(msg)//')'
            r%t_end_reached = t
            return
         end if
         a(0) = 0.0_dp
         a(1:n) = rhs(1:n)
         a(fixed_nodes) = 0.0_dp
         lam = 0.0_dp
         do j = 1, na
            lam(idx(j)) = rhs(n + j)
         end do
      end subroutine equilibrium_acceleration

      subroutine contact_state()
         integer :: k
         do k = 1, nc
            pen(k) = u(m%con_a(k)) - u(m%con_b(k)) - m%con_gap(k)
            force(k) = lam(k)
         end do
      end subroutine contact_state

      !> Phases: an impact opens one at t_n + αh with v_in = v_imp; an elastic/partly elastic
      !> impact closes it at once (v_out = δ̇_{n+1}), a plastic one stays open while the
      !> contact is held and closes at the release step.
      subroutine track_events()
         integer :: k
         if (impact) then
            k = imp_c
            if (ph_open(k)) call close_phase(k, t_prev, vn(m%con_a(k)) - vn(m%con_b(k)))
            ph_open(k) = .true.
            ph_t(k) = t_prev + alpha_imp*h; ph_v(k) = v_imp
            ph_pen(k) = max(pen(k), 0.0_dp); ph_f(k) = force(k)
            r%impacts(k) = r%impacts(k) + 1
            r%counters(C_EVENTS) = r%counters(C_EVENTS) + 1_i8
            if (.not. pers(k)) call close_phase(k, ph_t(k), v(m%con_a(k)) - v(m%con_b(k)))
         end if
         do k = 1, nc
            if (.not. ph_open(k)) cycle
            ph_pen(k) = max(ph_pen(k), pen(k)); ph_f(k) = max(ph_f(k), force(k))
            if (.not. pers(k)) call close_phase(k, t_prev, vn(m%con_a(k)) - vn(m%con_b(k)))
         end do
      end subroutine track_events

      subroutine close_phase(k, t_off, v_out)
         integer, intent(in) :: k
         real(dp), intent(in) :: t_off, v_out
         call results_add_event(r, k, [ph_t(k), t_off, ph_v(k), v_out, ph_pen(k), ph_f(k)])
         ph_open(k) = .false.
      end subroutine close_phase

      subroutine close_open_phases()
         integer :: k
         do k = 1, nc
            if (ph_open(k)) call results_add_event(r, k, [ph_t(k), -1.0_dp, ph_v(k), 0.0_dp, &
                                                          ph_pen(k), ph_f(k)])
         end do
      end subroutine close_open_phases

      !> E_IMPACT is what Newton's law takes out at each impact, ½ m*(v_in² − v_out²) with the
      !> contact's effective mass; the balance then shows how far the tuned Newmark step is
      !> from the stereomechanical impact plus the smooth work.
      subroutine record()
         real(dp) :: e(NENERGY)
         e = energy_terms(e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, d_links, &
                          d_contact, d_impact, 0.0_dp, 0.0_dp)
         r%energy = e
         r%energy_balance_max = max(r%energy_balance_max, abs(e(E_BALANCE)))
         call results_record(r, t, u(1:n), v(1:n), a(1:n), pen, force, e, ms%link_f, ms%link_u)
      end subroutine record

   end subroutine run_newmark_lagrange
end module martello_newmark_lagrange
