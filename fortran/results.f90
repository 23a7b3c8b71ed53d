!> What a dynamic run produces, whatever integrator made it: a decimated history, contact
!> events (one per contact phase), peaks over every step (not only the recorded ones), the
!> energy balance and the cost counters. Native integrators (Fortran and C) fill it through
!> the same procedures, so every method is measured the same way.
module martello_results
   use martello_kinds, only: dp, i8
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   implicit none
   private
   public :: results_t, results_init, results_record, results_add_event, results_track, &
      energy_terms, free_side_crossing, &
      NCOUNTERS, C_STEPS, C_REJECTED, C_NEWTON, C_RESIDUALS, C_FACTORIZATIONS, C_EVENTS, &
      C_JACOBIANS, C_ROOT_EVALS, C_CHATTER, NENERGY, E_KINETIC, E_RECOVERABLE, E_INPUT, E_DAMPING, &
      E_PLASTIC, E_CONTACT, E_BALANCE, E_INITIAL, E_IMPACT, NEVENT, EV_T_ON, EV_T_OFF, &
      EV_V_IN, EV_V_OUT, EV_MAX_PEN, EV_MAX_FORCE

   ! cost counters
   integer, parameter :: NCOUNTERS = 9
   integer, parameter :: C_STEPS = 1, C_REJECTED = 2, C_NEWTON = 3, C_RESIDUALS = 4, &
                         C_FACTORIZATIONS = 5, C_EVENTS = 6, C_JACOBIANS = 7, C_ROOT_EVALS = 8, &
                         C_CHATTER = 9
   ! energy terms [J]: balance = initial + input − kinetic − recoverable − dissipated (≈ 0)
   integer, parameter :: NENERGY = 9
   integer, parameter :: E_KINETIC = 1, E_RECOVERABLE = 2, E_INPUT = 3, E_DAMPING = 4, &
                         E_PLASTIC = 5, E_CONTACT = 6, E_BALANCE = 7, E_INITIAL = 8, E_IMPACT = 9
   ! one contact phase
   integer, parameter :: NEVENT = 6
   integer, parameter :: EV_T_ON = 1, EV_T_OFF = 2, EV_V_IN = 3, EV_V_OUT = 4, &
                         EV_MAX_PEN = 5, EV_MAX_FORCE = 6

   type :: results_t
      ! history: hist(:, k) = [t, (u, v, a of each output node), (δ, P of each output
      ! contact), energy(1:NENERGY)]
      integer :: ncol = 0, nrec = 0
      real(dp), allocatable :: hist(:, :)
      integer, allocatable :: out_nodes(:), out_contacts(:), out_links(:)
      ! events
      integer :: nevents = 0
      integer, allocatable :: ev_contact(:)
      real(dp), allocatable :: ev(:, :)
      ! peaks over every accepted step
      real(dp), allocatable :: u_max(:), u_min(:), v_absmax(:), a_absmax(:)
      !> the largest local maximum of u, interpolated between steps (u_peak at t_peak); the
      !> step maxima above are O(h) in time, these are O(h²)
      real(dp), allocatable :: u_peak(:), t_peak(:)
      real(dp), allocatable :: pen_max(:), force_max(:)
      !> per link: max |force| and max |elongation| (storey shear and drift of a frame);
      !> NaN when the integrator does not report link states
      real(dp), allocatable :: link_force_absmax(:), link_du_absmax(:)
      integer, allocatable :: impacts(:)
      real(dp) :: energy(NENERGY) = 0.0_dp
      real(dp) :: energy_balance_max = 0.0_dp   !< max |balance| over the run
      integer(i8) :: counters(NCOUNTERS) = 0_i8
      real(dp) :: t_end_reached = 0.0_dp
      real(dp) :: dt_critical = 0.0_dp          !< explicit stability limit (0: not computed)
      real(dp) :: omega_max = 0.0_dp
      character(len=512) :: message = ''
      ! the previous accepted state, for the interpolated peaks of results_track
      real(dp), allocatable :: prev_u(:), prev_v(:), prev_a(:)
      real(dp) :: prev_t = -1.0_dp
   end type results_t

contains

   subroutine results_init(r, n_nodes, n_contacts, out_nodes, out_contacts, capacity, n_links, out_links)
      type(results_t), intent(inout) :: r
      integer, intent(in) :: n_nodes, n_contacts, out_nodes(:), out_contacts(:), capacity
      integer, intent(in), optional :: n_links, out_links(:)
      integer :: nl
      r%out_nodes = out_nodes; r%out_contacts = out_contacts
      if (present(out_links)) then
         r%out_links = out_links
      else
         allocate (r%out_links(0))
      end if
      nl = 0
      if (present(n_links)) nl = n_links
      if (allocated(r%link_force_absmax)) deallocate (r%link_force_absmax, r%link_du_absmax)
      allocate (r%link_force_absmax(nl), r%link_du_absmax(nl))
      r%link_force_absmax = ieee_value(1.0_dp, ieee_quiet_nan)
      r%link_du_absmax = ieee_value(1.0_dp, ieee_quiet_nan)
      r%ncol = 1 + 3*size(out_nodes) + 2*size(out_contacts) + 2*size(r%out_links) + NENERGY
      r%nrec = 0
      if (allocated(r%hist)) deallocate (r%hist)
      allocate (r%hist(r%ncol, max(capacity, 2)))
      r%nevents = 0
      if (allocated(r%ev)) deallocate (r%ev, r%ev_contact)
      allocate (r%ev(NEVENT, 16), r%ev_contact(16))
      if (allocated(r%u_max)) deallocate (r%u_max, r%u_min, r%v_absmax, r%a_absmax, &
                                          r%pen_max, r%force_max, r%impacts, r%u_peak, r%t_peak)
      allocate (r%u_max(n_nodes), r%u_min(n_nodes), r%v_absmax(n_nodes), r%a_absmax(n_nodes), &
                r%pen_max(n_contacts), r%force_max(n_contacts), r%impacts(n_contacts), &
                r%u_peak(n_nodes), r%t_peak(n_nodes))
      r%u_peak = -huge(1.0_dp); r%t_peak = -1.0_dp
      r%u_max = -huge(1.0_dp); r%u_min = huge(1.0_dp); r%v_absmax = 0.0_dp
      r%a_absmax = 0.0_dp; r%pen_max = -huge(1.0_dp); r%force_max = 0.0_dp; r%impacts = 0
      if (allocated(r%prev_u)) deallocate (r%prev_u, r%prev_v, r%prev_a)
      allocate (r%prev_u(n_nodes), r%prev_v(n_nodes), r%prev_a(n_nodes))
      r%prev_t = -1.0_dp
      r%energy = 0.0_dp; r%energy_balance_max = 0.0_dp
      r%counters = 0_i8
      r%message = ''
   end subroutine results_init

   !> Append one history row (grows by doubling when a variable-step integrator needs it).
   subroutine results_record(r, t, u, v, a, pen, force, energy, link_f, link_du)
      type(results_t), intent(inout) :: r
      real(dp), intent(in) :: t, u(:), v(:), a(:), pen(:), force(:), energy(NENERGY)
      real(dp), intent(in), optional :: link_f(:), link_du(:)   !< absent: NaN columns
      real(dp), allocatable :: tmp(:, :)
      integer :: k, c
      if (r%nrec == size(r%hist, 2)) then
         allocate (tmp(r%ncol, 2*size(r%hist, 2)))
         tmp(:, 1:r%nrec) = r%hist(:, 1:r%nrec)
         call move_alloc(tmp, r%hist)
      end if
      r%nrec = r%nrec + 1
      k = r%nrec; c = 1
      r%hist(c, k) = t
      r%hist(c + 1:c + size(r%out_nodes), k) = u(r%out_nodes); c = c + size(r%out_nodes)
      r%hist(c + 1:c + size(r%out_nodes), k) = v(r%out_nodes); c = c + size(r%out_nodes)
      r%hist(c + 1:c + size(r%out_nodes), k) = a(r%out_nodes); c = c + size(r%out_nodes)
      r%hist(c + 1:c + size(r%out_contacts), k) = pen(r%out_contacts); c = c + size(r%out_contacts)
      r%hist(c + 1:c + size(r%out_contacts), k) = force(r%out_contacts); c = c + size(r%out_contacts)
      if (present(link_f) .and. present(link_du)) then
         r%hist(c + 1:c + size(r%out_links), k) = link_f(r%out_links); c = c + size(r%out_links)
         r%hist(c + 1:c + size(r%out_links), k) = link_du(r%out_links); c = c + size(r%out_links)
      else
         r%hist(c + 1:c + 2*size(r%out_links), k) = ieee_value(1.0_dp, ieee_quiet_nan)
         c = c + 2*size(r%out_links)
      end if
      r%hist(c + 1:c + NENERGY, k) = energy
   end subroutine results_record

   subroutine results_add_event(r, contact, values)
      type(results_t), intent(inout) :: r
      integer, intent(in) :: contact
      real(dp), intent(in) :: values(NEVENT)
      real(dp), allocatable :: tmp(:, :)
      integer, allocatable :: itmp(:)
      if (r%nevents == size(r%ev, 2)) then
         allocate (tmp(NEVENT, 2*size(r%ev, 2)), itmp(2*size(r%ev, 2)))
         tmp(:, 1:r%nevents) = r%ev(:, 1:r%nevents)
         itmp(1:r%nevents) = r%ev_contact(1:r%nevents)
         call move_alloc(tmp, r%ev); call move_alloc(itmp, r%ev_contact)
      end if
      r%nevents = r%nevents + 1
      r%ev(:, r%nevents) = values
      r%ev_contact(r%nevents) = contact
   end subroutine results_add_event
   !> Peaks over every accepted state (call once per accepted step, from any integrator):
   !> extremes of u, |v|, |a|, penetration and force, and the largest local maximum of u
   !> interpolated between the previous and this state by u + vτ + ½aτ², τ = −v/a (O(h²) in
   !> time where the step maxima are O(h)).
   subroutine results_track(r, t, u, v, a, pen, force, link_f, link_du, u_prev, v_prev, a_prev)
      type(results_t), intent(inout) :: r
      real(dp), intent(in) :: t, u(:), v(:), a(:), pen(:), force(:)
      real(dp), intent(in), optional :: link_f(:), link_du(:)
      !> the previous accepted state, if the caller keeps it (saves a copy per step)
      real(dp), intent(in), optional :: u_prev(:), v_prev(:), a_prev(:)
      integer :: i
      real(dp) :: tau, up, h
      h = t - r%prev_t
      if (present(u_prev)) then
         call peaks(u_prev, v_prev, a_prev)
      else
         call peaks(r%prev_u, r%prev_v, r%prev_a)
         r%prev_u = u; r%prev_v = v; r%prev_a = a
      end if
      r%prev_t = t
      do i = 1, size(pen)
         r%pen_max(i) = max(r%pen_max(i), pen(i))
         r%force_max(i) = max(r%force_max(i), force(i))
      end do
      if (present(link_f) .and. present(link_du)) then
         do i = 1, size(link_f)
            ! written as "not ≥" so that the NaN the maxima start from is replaced
            if (.not. (r%link_force_absmax(i) >= abs(link_f(i)))) r%link_force_absmax(i) = abs(link_f(i))
            if (.not. (r%link_du_absmax(i) >= abs(link_du(i)))) r%link_du_absmax(i) = abs(link_du(i))
         end do
      end if
   contains
      subroutine peaks(un, vn, an)
         real(dp), intent(in) :: un(:), vn(:), an(:)
         associate (umax => r%u_max, umin => r%u_min, vmax => r%v_absmax, amax => r%a_absmax, &
                    upk => r%u_peak, tpk => r%t_peak)
            do i = 1, size(u)
               umax(i) = max(umax(i), u(i)); umin(i) = min(umin(i), u(i))
               vmax(i) = max(vmax(i), abs(v(i))); amax(i) = max(amax(i), abs(a(i)))
               if (r%prev_t >= 0.0_dp .and. vn(i) > 0.0_dp .and. v(i) <= 0.0_dp) then
                  if (an(i) < 0.0_dp) then
                     tau = min(-vn(i)/an(i), h)
                     up = un(i) + vn(i)*tau + 0.5_dp*an(i)*tau*tau
                     if (up > upk(i)) then
                        upk(i) = up; tpk(i) = r%prev_t + tau
                     end if
                  end if
               end if
            end do
         end associate
      end subroutine peaks
   end subroutine results_track
   !> The energy terms of a run from its accumulated works (W: trapezoidal, since t = 0) and
   !> recoverable energies: the dissipation of links (plasticity) and contacts is their work
   !> minus the change of their recoverable energy, so the balance is the work–energy identity
   !> KE0 + W_ext − KE − W_damp − W_links − W_contact − W_impact (≈ 0 to the method's accuracy).
   !> ke_corr, ke_corr0: a method's correction to ½vᵀMv in its conserved energy, now and at
   !> t = 0 (central difference; 0 for the others).
   pure function energy_terms(e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, &
                              d_links, d_contact, d_impact, ke_corr, ke_corr0) result(e)
      real(dp), intent(in) :: e0, w_ext, e_kin, e_links, e_cont, e_links0, e_cont0, d_damp, &
                              d_links, d_contact, d_impact, ke_corr, ke_corr0
      real(dp) :: e(NENERGY)
      e = 0.0_dp
      e(E_KINETIC) = e_kin; e(E_RECOVERABLE) = e_links + e_cont; e(E_INPUT) = w_ext
      e(E_DAMPING) = d_damp
      e(E_PLASTIC) = d_links - (e_links - e_links0)
      e(E_CONTACT) = d_contact - (e_cont - e_cont0)
      e(E_INITIAL) = e0
      e(E_IMPACT) = d_impact
      e(E_BALANCE) = (e0 - ke_corr0) + w_ext - (e_kin - ke_corr) - e(E_RECOVERABLE) - e(E_DAMPING) &
                     - e(E_PLASTIC) - e(E_CONTACT) - e(E_IMPACT)
   end function energy_terms

   !> Event location on the free side of a step: the first root of d + rate·τ + ½acc·τ² in
   !> [lo, hi] (O(h³) in time when the free motion is smooth); linear fallback, else hi.
   pure real(dp) function free_side_crossing(d, rate, acc, lo, hi) result(tau)
      real(dp), intent(in) :: d, rate, acc, lo, hi
      real(dp) :: disc, t1, t2, q
      tau = hi
      if (abs(acc) > 0.0_dp) then
         disc = rate*rate - 2.0_dp*acc*d
         if (disc >= 0.0_dp) then
            q = -0.5_dp*(rate + sign(sqrt(disc), rate))
            if (q /= 0.0_dp) then
               t1 = q/(0.5_dp*acc); t2 = d/q
            else
               t1 = 0.0_dp; t2 = 0.0_dp
            end if
            if (t1 >= lo .and. t1 <= hi .and. (t1 <= t2 .or. t2 < lo .or. t2 > hi)) then
               tau = t1; return
            end if
            if (t2 >= lo .and. t2 <= hi) then
               tau = t2; return
            end if
         end if
      end if
      if (rate /= 0.0_dp) then
         tau = -d/rate
         tau = min(max(tau, lo), hi)
      end if
   end function free_side_crossing
end module martello_results
