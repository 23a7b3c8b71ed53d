!> Moreau–Jean time stepping (Moreau 1988; Jean 1999; Acary & Brogliato 2008, §10.1) for
!> scenes with restitution and Lagrange contacts, penalty contacts and links being smooth
!> forces:
!>
!>   M (v_{k+1} − v_k) = h f_θ + Bᵀ p_{k+1},   q_{k+1} = q_k + h v_θ,   x_θ = θ x_{k+1} + (1−θ) x_k,
!>
!> with the smooth forces linearised at the start of the step with their tangents K, C
!> (f_θ ≈ f_ext,θ − fint_k − θ K Δq − θ C Δv), so that the step matrix is
!> Ŵ = M + hθ C + h²θ² K (banded, factorised once a step) and the free velocity is
!> v_free = v_k + Ŵ⁻¹ h (f_ext,θ − fint_k − hθ K v_k) (Acary & Brogliato 2008, eq. 10.12).
!> Contacts are predicted active when the gap at mid-step, extrapolated from the start,
!> has closed: δ(q_k + ½h v_k) ≥ 0 (the index set of Siconos' MoreauJeanOSI, γ = ½ whatever
!> θ). On them Newton's impact law holds at the velocity level,
!>
!>   0 ≤ ġ_{k+1} + e ġ_k ⊥ p_{k+1} ≥ 0,   ġ = B v = v_b − v_a = −δ̇,
!>
!> an LCP on the Delassus operator W = B Ŵ⁻¹ Bᵀ, the shared impulse problem (martello_impulse,
!> docs/impulse.md: Lemke for up to LEMKE_MAX active contacts, projected Gauss–Seidel beyond,
!> on a tridiagonal W when Ŵ is diagonal). Lagrange contacts are the same law with e = their
!> restitution (default 0).
!>
!> Discrete energy identity (linear forces): E_{k+1} − E_k = −(θ − ½)(‖Δv‖²_M + ‖Δq‖²_K)
!> + Δqᵀ f_ext,θ + ġ_θᵀ p_{k+1}; the impulse work ġ_θ p = (1 − θ(1+e)) ġ_k p is ≤ 0 iff
!> θ(1+e) ≤ 1. E_IMPACT accumulates −ġ_θᵀ p; the θ-dissipation is what E_BALANCE shows
!> (zero up to round-off for θ = ½ and linear forces).
module martello_moreau_jean
   use martello_kinds, only: dp, i8
   use martello_lapack, only: dgbtrf, dgbtrs
   use martello_status
   use martello_model, only: model_t, model_bandwidth, rigid_contact_sides
   use martello_band_matrix, only: band_t, band_init, band_matvec
   use martello_assembly, only: mech_state_t, mech_init, internal_forces, external_forces, &
      mech_commit, recoverable_energy, mass_times, assemble_mass, kinetic_energy
   use martello_results
   use martello_run_checks, only: check_run_settings, check_divergence
   use martello_integrator_settings, only: integrator_settings_t, integrator_name, scheme_supported
   use martello_impulse, only: contact_graph_t, contact_graph, delassus_columns, &
      delassus_bandwidth, delassus_diagonal_band, newton_impulses, IMPULSE_OK
   use martello_linalg, only: lapack_status
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   implicit none
   private
   public :: run_moreau_jean


contains

   !> Run a scene from t = 0 to t_end with a fixed step. stat < 0 on failure, with
   !> r%message saying where and why (the results so far stay in r for diagnosis).
   subroutine run_moreau_jean(m, s, r, stat)
      type(model_t), intent(inout) :: m
      type(integrator_settings_t), intent(in) :: s
      type(results_t), intent(inout) :: r
      integer, intent(out) :: stat

      integer :: n, kd, nc, nsteps, step, i, j, c, na, kw, info, iters
      real(dp), allocatable :: u(:), v(:), un(:), vn(:), a(:), fint(:), fint_n(:), fext(:), &
                               fext_n(:), rhs(:), work(:), mrow(:), ma(:)
      real(dp), allocatable :: e_con(:), p(:), p_prev(:), pen(:), force(:)
      integer, allocatable :: sa(:), sb(:), act(:), pos(:), fixed_nodes(:), ipiv(:)
      type(contact_graph_t) :: graph
      ! Delassus operator: dense (kd > 0, from the columns Ŵ⁻¹Bᵀ) or band (kd = 0), LCP data
      real(dp), allocatable :: wd_(:, :), wb(:, :), zcol(:, :), qlcp(:), zlcp(:), gref(:), eact(:)
      ! open contact phases
      real(dp), allocatable :: ph_t(:), ph_v(:), ph_pen(:), ph_f(:), ph_last(:)
      logical, allocatable :: ph_open(:), rigid(:), movable(:)
      type(mech_state_t) :: ms
      type(band_t) :: kband, cband, what
      real(dp) :: h, t, t_prev, theta, hth, hth2, e_kin, e_links, e_cont, e_links0, e_cont0, e0, &
                  w_ext, d_damp, d_links, d_contact, d_impact, w_abs, wdl, wll, wcl, e_mech, &
                  dw, gdot_theta, t_imp
      logical :: recording, thomas
      integer, parameter :: ENERGY_CHECK = 16

      stat = MARTELLO_OK
      n = m%n
      nc = m%ncontact
      t = 0.0_dp
      call check_scene(stat)
      if (stat /= MARTELLO_OK) return
      h = s%dt
      theta = s%theta
      hth = h*theta
      hth2 = hth*hth
      ! whole steps until t_end is reached; the last time is nsteps·h (reported as t_reached)
      nsteps = max(1, ceiling(s%t_end/h*(1.0_dp - 1.0e-12_dp)))
      kd = model_bandwidth(m)

      allocate (u(0:n), v(0:n), un(0:n), vn(0:n), a(0:n), fint(0:n), fint_n(0:n), fext(0:n), &
                fext_n(0:n), rhs(0:n), work(0:n), mrow(0:n), ma(0:n), ipiv(n))
      allocate (e_con(nc), p(nc), p_prev(nc), pen(nc), force(nc), sa(nc), sb(nc), act(nc), &
                pos(nc), rigid(nc), movable(nc))
      allocate (ph_t(nc), ph_v(nc), ph_pen(nc), ph_f(nc), ph_last(nc), ph_open(nc))
      ph_open = .false.
      p = 0.0_dp; p_prev = 0.0_dp; pen = 0.0_dp; force = 0.0_dp
      fixed_nodes = pack([(j, j = 1, n)], m%fixed)
      call band_init(kband, n, kd)
      call band_init(cband, n, kd)
      call band_init(what, n, kd)

      call rigid_contact_sides(m, rigid, e_con, sa, sb, movable)
      call contact_graph(n, sa, sb, movable, graph)

      ! initial state
      u(0) = 0.0_dp; v(0) = 0.0_dp
      u(1:n) = m%u0; v(1:n) = merge(0.0_dp, m%v0, m%fixed)
      a = 0.0_dp
      work = 1.0_dp; work(0) = 0.0_dp
      call mass_times(m, work, mrow)
      call mech_init(m, ms, u, v)
      kband%ab = 0.0_dp; cband%ab = 0.0_dp
      call internal_forces(m, ms, u, v, fint, kband%ab, 1.0_dp, 0.0_dp, cband%ab)
      call mech_commit(m, ms, u)
      call external_forces(m, mrow, 0.0_dp, fext)
      r%counters(C_RESIDUALS) = r%counters(C_RESIDUALS) + 1_i8
      r%counters(C_JACOBIANS) = r%counters(C_JACOBIANS) + 1_i8

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
         un = u; vn = v; fint_n = fint; fext_n = fext
         t_prev = t
         t = step*h
         call external_forces(m, mrow, t, fext)

         ! Ŵ = M + hθ C + h²θ² K from the tangents of the committed state
         what%ab = hth2*kband%ab + hth*cband%ab
         call assemble_mass(m, 1.0_dp, what)
         do i = 1, size(fixed_nodes)
            call pin_row(what, fixed_nodes(i))
         end do
         ! free velocity: Ŵ Δv_free = h (f_ext,θ − fint_k − hθ K v_k)
         call band_matvec(kband, vn(1:n), work(1:n))
         do i = 1, n
            rhs(i) = (h*theta)*fext(i) + (h*(1.0_dp - theta))*fext_n(i) - h*fint_n(i) - h*hth*work(i)
         end do
         rhs(0) = 0.0_dp
         rhs(fixed_nodes) = 0.0_dp
         call factorise(info)
         if (info /= 0) then
            call lapack_status('dgbtrf', info, stat, r%message)
            r%message = 'Moreau-Jean: the step matrix M + h theta C + (h theta)^2 K is singular ('// &
               trim(r%message)//')'
            r%t_end_reached = t_prev
            return
         end if
         call solve_what(rhs(1:n))
         v(1:n) = vn(1:n) + rhs(1:n)           ! v_free
         v(0) = 0.0_dp

         ! index set and impulses
         call active_set()
         p_prev = p
         p = 0.0_dp
         if (na > 0) then
            call impulses(info)
            if (stat /= MARTELLO_OK) return
            ! v = v_free + Ŵ⁻¹ Bᵀ p
            work = 0.0_dp
            do j = 1, na
               c = act(j)
               work(sa(c)) = work(sa(c)) - p(c)
               work(sb(c)) = work(sb(c)) + p(c)
            end do
            work(0) = 0.0_dp
            call solve_what(work(1:n))
            v(1:n) = v(1:n) + work(1:n)
         end if
         v(fixed_nodes) = 0.0_dp
         ! q_{k+1} = q_k + h (θ v_{k+1} + (1−θ) v_k), in the order of Siconos' updatePosition
         do i = 1, n
            u(i) = ((h*theta)*v(i) + (h*(1.0_dp - theta))*vn(i)) + un(i)
         end do
         u(fixed_nodes) = un(fixed_nodes)
         a(1:n) = (v(1:n) - vn(1:n))/h         ! mean acceleration of the step (impulses included)

         ! smooth forces and tangents at the new state, committed
         kband%ab = 0.0_dp; cband%ab = 0.0_dp
         call internal_forces(m, ms, u, v, fint, kband%ab, 1.0_dp, 0.0_dp, cband%ab)
         call mech_commit(m, ms, u, wdl, wll, wcl)
         r%counters(C_RESIDUALS) = r%counters(C_RESIDUALS) + 1_i8
         r%counters(C_JACOBIANS) = r%counters(C_JACOBIANS) + 1_i8
         r%counters(C_STEPS) = r%counters(C_STEPS) + 1_i8

         ! energy: external work Δqᵀ f_ext,θ; impulse work ġ_θ p (dissipated: its negative)
         d_damp = d_damp + wdl; d_links = d_links + wll; d_contact = d_contact + wcl
         dw = 0.0_dp
         do i = 1, n
            if (.not. m%fixed(i)) dw = dw + (theta*fext(i) + (1.0_dp - theta)*fext_n(i))*(u(i) - un(i))
         end do
         w_ext = w_ext + dw; w_abs = w_abs + abs(dw)
         do j = 1, na
            c = act(j)
            gdot_theta = theta*(v(sb(c)) - v(sa(c))) + (1.0_dp - theta)*(vn(sb(c)) - vn(sa(c)))
            d_impact = d_impact - gdot_theta*p(c)
         end do

         call contact_state()
         call track_events()
         call results_track(r, t, u(1:n), v(1:n), a(1:n), pen, force, ms%link_f, ms%link_u)
         recording = mod(step, s%every) == 0 .or. step == nsteps
         if (.not. (recording .or. mod(step, ENERGY_CHECK) == 0 .or. &
                    .not. ieee_is_finite(dw + d_impact + d_links + d_contact + d_damp))) cycle
         e_kin = kinetic_energy(m, v, ma)
         call recoverable_energy(m, ms, u, e_links, e_cont)
         if (recording) call record()
         e_mech = e_kin + e_links + e_cont
         call check_divergence(s, t, e_mech, e0, w_abs, u, v, &
                               'the linearised smooth forces need a smaller step', r, stat)
         if (stat /= MARTELLO_OK) return
      end do
      call close_open_phases()
      r%t_end_reached = t

   contains

      subroutine check_scene(st)
         integer, intent(out) :: st
         call check_run_settings(m, s, r, st)
         if (st /= MARTELLO_OK) return
         if (.not. (s%theta >= 0.5_dp .and. s%theta <= 1.0_dp)) then
            st = MARTELLO_ERR_ARGUMENT
            r%message = 'Moreau-Jean: theta must lie in [0.5, 1] (theta < 1/2 is unstable)'
            return
         end if
      end subroutine check_scene


      !> Replace row and column i by the identity (a fixed DOF: Δv_i = 0).
      subroutine pin_row(b, i)
         type(band_t), intent(inout) :: b
         integer, intent(in) :: i
         integer :: jj, rr
         rr = 2*b%kd + 1
         do jj = max(1, i - b%kd), min(n, i + b%kd)
            b%ab(rr + i - jj, jj) = 0.0_dp
            b%ab(rr + jj - i, i) = 0.0_dp
         end do
         b%ab(rr, i) = 1.0_dp
      end subroutine pin_row

      !> LU of Ŵ once a step (a diagonal Ŵ needs none); info > 0: singular. A chain (kd = 1)
      !> is factorised without pivoting — Ŵ is symmetric positive definite, diagonally
      !> dominant while M dominates h²θ²K — with dgbtrf taking over if a pivot collapses.
      subroutine factorise(inf)
         integer, intent(out) :: inf
         integer :: k
         inf = 0
         r%counters(C_FACTORIZATIONS) = r%counters(C_FACTORIZATIONS) + 1_i8
         thomas = .false.
         select case (kd)
         case (0)
            do k = 1, n
               if (what%ab(1, k) == 0.0_dp) then
                  inf = k; return
               end if
            end do
         case (1)
            ! A(k,k) = ab(3,k), A(k+1,k) = ab(4,k), A(k,k+1) = ab(2,k+1)
            what%d = what%ab(3, :)
            thomas = .true.
            do k = 2, n
               if (abs(what%d(k - 1)) <= 1.0e-14_dp*abs(what%ab(3, k - 1))) then
                  thomas = .false.; exit
               end if
               what%dl(k) = what%ab(4, k - 1)/what%d(k - 1)
               what%d(k) = what%d(k) - what%dl(k)*what%ab(2, k)
            end do
            if (thomas .and. what%d(n) == 0.0_dp) thomas = .false.
            if (.not. thomas) call dgbtrf(n, n, kd, kd, what%ab, size(what%ab, 1), ipiv, inf)
         case default
            call dgbtrf(n, n, kd, kd, what%ab, size(what%ab, 1), ipiv, inf)
         end select
      end subroutine factorise

      subroutine solve_what(x)
         real(dp), intent(inout) :: x(:)
         integer :: inf, k
         if (kd == 0) then
            x = x/what%ab(1, :)
         else if (thomas) then
            do k = 2, n
               x(k) = x(k) - what%dl(k)*x(k - 1)
            end do
            x(n) = x(n)/what%d(n)
            do k = n - 1, 1, -1
               x(k) = (x(k) - what%ab(2, k + 1)*x(k + 1))/what%d(k)
            end do
         else
            call dgbtrs('N', n, kd, kd, 1, what%ab, size(what%ab, 1), ipiv, x, n, inf)
         end if
      end subroutine solve_what

      !> Acary's index set: δ(q_k + ½h v_k) ≥ 0, the gap extrapolated to mid-step has closed.
      subroutine active_set()
         real(dp) :: dpred
         integer :: k
         na = 0
         pos = 0
         do k = 1, nc
            if (.not. movable(k)) cycle
            dpred = (un(m%con_a(k)) + (0.5_dp*h)*vn(m%con_a(k))) &
                    - (un(m%con_b(k)) + (0.5_dp*h)*vn(m%con_b(k))) - m%con_gap(k)
            if (dpred >= 0.0_dp) then
               na = na + 1
               act(na) = k
               pos(k) = na
            end if
         end do
      end subroutine active_set

      !> W of the active contacts (martello_impulse) and Newton's law on them; p(act) the
      !> impulses. ġ_free = B v_free, ġ_ref = B v_k.
      subroutine impulses(inf)
         integer, intent(out) :: inf
         integer :: ii, jj, k
         inf = 0
         if (allocated(qlcp)) then
            if (size(qlcp) < na) deallocate (qlcp, zlcp, gref, eact)
         end if
         if (.not. allocated(qlcp)) allocate (qlcp(nc), zlcp(nc), gref(nc), eact(nc))
         do ii = 1, na
            k = act(ii)
            qlcp(ii) = v(sb(k)) - v(sa(k))
            gref(ii) = vn(sb(k)) - vn(sa(k))
            eact(ii) = e_con(k)
            zlcp(ii) = p_prev(k)                   ! warm start from the last step (PGS)
         end do
         if (kd == 0) then
            ! Ŵ diagonal: W banded in the active ordering (tridiagonal for a chain)
            kw = delassus_bandwidth(graph, sa, sb, act(1:na), pos)
            call ensure_band(kw)
            call delassus_diagonal_band(graph, sa, sb, act(1:na), pos, what%ab(1, :), kw, wb)
            call newton_impulses(qlcp(1:na), gref(1:na), eact(1:na), zlcp(1:na), inf, iters, &
                                 wb=wb, kw=kw)
         else
            ! W = B Ŵ⁻¹ Bᵀ from the columns Ŵ⁻¹ B_jᵀ (one multi-right-hand-side solve)
            if (allocated(zcol)) then
               if (size(zcol, 2) < na) deallocate (zcol)
            end if
            if (.not. allocated(zcol)) allocate (zcol(n, max(na, 1)))
            zcol(:, 1:na) = 0.0_dp
            do jj = 1, na
               k = act(jj)
               if (sa(k) > 0) zcol(sa(k), jj) = -1.0_dp
               if (sb(k) > 0) zcol(sb(k), jj) = 1.0_dp
            end do
            if (thomas) then
               do jj = 1, na
                  call solve_what(zcol(:, jj))
               end do
            else
               call dgbtrs('N', n, kd, kd, na, what%ab, size(what%ab, 1), ipiv, zcol, n, inf)
            end if
            call ensure_dense()
            call delassus_columns(sa(act(1:na)), sb(act(1:na)), zcol(:, 1:na), wd_(1:na, 1:na))
            call newton_impulses(qlcp(1:na), gref(1:na), eact(1:na), zlcp(1:na), inf, iters, &
                                 w=wd_(1:na, 1:na))
         end if
         r%counters(C_NEWTON) = r%counters(C_NEWTON) + int(iters, i8)
         if (inf /= IMPULSE_OK) then
            write (r%message, '(a,i0,a,es12.5,a,i0,a)') 'Moreau-Jean: the impulse LCP on ', na, &
               ' active contacts failed at t = ', t, ' s (', iters, &
               ' iterations; redundant constraints or a contact between immobile sides?)'
            stat = MARTELLO_ERR_NOT_CONVERGED; r%t_end_reached = t_prev
            return
         end if
         do ii = 1, na
            p(act(ii)) = zlcp(ii)
         end do
      end subroutine impulses

      subroutine ensure_band(k)
         integer, intent(in) :: k
         if (allocated(wb)) then
            if (size(wb, 1) < 2*k + 1 .or. size(wb, 2) < na) deallocate (wb)
         end if
         if (.not. allocated(wb)) allocate (wb(2*k + 1, max(na, nc)))
      end subroutine ensure_band

      subroutine ensure_dense()
         if (allocated(wd_)) then
            if (size(wd_, 1) < na) deallocate (wd_)
         end if
         if (.not. allocated(wd_)) allocate (wd_(na, na))
      end subroutine ensure_dense

      !> Penetration and force of every contact at the current state: penalty contacts from
      !> the committed law, rigid ones δ = u_a − u_b − gap and the mean force p/h.
      subroutine contact_state()
         integer :: k
         do k = 1, nc
            if (rigid(k)) then
               pen(k) = u(m%con_a(k)) - u(m%con_b(k)) - m%con_gap(k)
               force(k) = p(k)/h
            else
               pen(k) = ms%con_pen(k); force(k) = ms%con_f(k)
            end if
         end do
      end subroutine contact_state

      !> Contact phases. Rigid contacts: a phase is a run of steps with p > 0; it starts at
      !> the instant t_k + (1−θ)h where the scheme's piecewise-linear path switches from v_k
      !> to v_{k+1} (q_{k+1} = q_k + (1−θ)h v_k + θh v_{k+1}), v_in is δ̇_k before the first
      !> impulse, v_out δ̇ after the last one, t_off the switching instant of the last
      !> impulse step (a single-step impact has t_off = t_on: it is instantaneous).
      !> Penalty contacts: δ > 0, onset and separation by linear interpolation of δ.
      subroutine track_events()
         integer :: k, ia, ib
         real(dp) :: d0, d1, tau
         do k = 1, nc
            ia = m%con_a(k); ib = m%con_b(k)
            if (rigid(k)) then
               t_imp = t_prev + (1.0_dp - theta)*(t - t_prev)
               if (p(k) > 0.0_dp) then
                  if (.not. ph_open(k)) then
                     ph_open(k) = .true.
                     ph_t(k) = t_imp; ph_v(k) = vn(ia) - vn(ib)
                     ph_pen(k) = -huge(1.0_dp); ph_f(k) = 0.0_dp
                     r%impacts(k) = r%impacts(k) + 1
                     r%counters(C_EVENTS) = r%counters(C_EVENTS) + 1_i8
                  end if
                  ph_last(k) = t_imp
                  ph_pen(k) = max(ph_pen(k), pen(k)); ph_f(k) = max(ph_f(k), force(k))
               else if (ph_open(k)) then
                  call results_add_event(r, k, [ph_t(k), ph_last(k), ph_v(k), vn(ia) - vn(ib), &
                                                max(ph_pen(k), 0.0_dp), ph_f(k)])
                  ph_open(k) = .false.
               end if
            else
               d0 = un(ia) - un(ib) - m%con_gap(k)
               d1 = pen(k)
               if (.not. ph_open(k) .and. ms%con_on(k)) then
                  tau = 0.0_dp
                  if (d1 > d0) tau = min(max(-d0/(d1 - d0), 0.0_dp), 1.0_dp)
                  ph_open(k) = .true.
                  ph_t(k) = t_prev + tau*(t - t_prev)
                  ph_v(k) = vn(ia) - vn(ib) + tau*((v(ia) - v(ib)) - (vn(ia) - vn(ib)))
                  ph_pen(k) = 0.0_dp; ph_f(k) = 0.0_dp
                  r%impacts(k) = r%impacts(k) + 1
                  r%counters(C_EVENTS) = r%counters(C_EVENTS) + 1_i8
               end if
               if (ph_open(k)) then
                  ph_pen(k) = max(ph_pen(k), pen(k)); ph_f(k) = max(ph_f(k), force(k))
                  if (.not. ms%con_on(k)) then
                     tau = 1.0_dp
                     if (d0 > d1) tau = min(max(d0/(d0 - d1), 0.0_dp), 1.0_dp)
                     call results_add_event(r, k, [ph_t(k), t_prev + tau*(t - t_prev), ph_v(k), &
                                                   vn(ia) - vn(ib) + tau*((v(ia) - v(ib)) - (vn(ia) - vn(ib))), &
                                                   ph_pen(k), ph_f(k)])
                     ph_open(k) = .false.
                  end if
               end if
            end if
         end do
      end subroutine track_events

      subroutine close_open_phases()
         integer :: k
         do k = 1, nc
            if (ph_open(k)) call results_add_event(r, k, [ph_t(k), -1.0_dp, ph_v(k), 0.0_dp, &
                                                          max(ph_pen(k), 0.0_dp), ph_f(k)])
         end do
      end subroutine close_open_phases

      !> Energy terms as in the structural integrators, plus E_IMPACT = −Σ ġ_θ p (the energy
      !> the impulses took out); E_BALANCE then holds the θ-dissipation and the error of the
      !> linearised nonlinear forces.
      subroutine record()
         real(dp) :: e(NENERGY)
         e = energy_terms(e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, d_links, &
                          d_contact, d_impact, 0.0_dp, 0.0_dp)
         r%energy = e
         r%energy_balance_max = max(r%energy_balance_max, abs(e(E_BALANCE)))
         call results_record(r, t, u(1:n), v(1:n), a(1:n), pen, force, e, ms%link_f, ms%link_u)
      end subroutine record
   end subroutine run_moreau_jean
end module martello_moreau_jean
