!> Forces of a scene at a trial state: internal forces of links and penalty contacts with
!> their tangents (assembled into a band matrix), external forces, recoverable energy and the
!> element work needed for the energy balance. Node arrays run 0:n with 0 = ground (always
!> at rest in the relative frame), so ground ends need no branches in the loops.
module martello_assembly
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK, out_of_memory, REAL_BYTES, INT_BYTES, FIX_SMALLER_SCENE
   use martello_model, only: model_t, SCHEME_PENALTY
   use martello_links, only: link_force, link_force_on_branch, BRANCH_FREE, bilinear_energy, LINK_SPRING, LINK_BAR, LINK_BILINEAR, &
      LINK_DASHPOT, LINK_FLUID_DAMPER, L_STIFF, L_DAMP, L_YIELD, L_HARDENING
   use martello_contact_laws, only: contact_force, contact_elastic_energy, LAW_LINEAR, LAW_KELVIN, &
      P_STIFF, P_DAMPING
   use martello_band_matrix, only: band_t, band_add
   use martello_element_rows, only: row_dot, row_add, row_stencil
   use martello_time_functions, only: tf_value, tf_next_breakpoint, tf_period, TF_NONE
   implicit none
   private
   public :: mech_state_t, mech_init, internal_forces, external_forces, mech_commit, &
      element_power, recoverable_energy, mass_times, external_work, kinetic_energy, &
      assemble_mass, uniform_acceleration, load_breakpoint, load_period, load_pattern, swap, ONSET_SPEED_FLOOR

   !> Hunt–Crossley-type laws scale damping by 1/v_in; a contact first seen while δ̇ ≤ 0
   !> (grazing, or a step that lands inside) uses this floor [m/s] instead of a division by 0.
   real(dp), parameter :: ONSET_SPEED_FLOOR = 1.0e-12_dp

   !> Branches of a penalty contact (con_branch): the whole law; open (no force whatever
   !> the gap); in contact (the law extended smoothly past delta = 0, Kelvin unclipped);
   !> Kelvin past its tension cut-off (no force while delta > 0).
   integer, parameter, public :: CONTACT_FREE = 0, CONTACT_OPEN = 1, CONTACT_ON = 2, &
      CONTACT_CUT = 3

   type :: mech_state_t
      ! committed link state (rate-independent force and elongation), and its trial
      real(dp), allocatable :: link_fc(:), link_u(:), link_fc_trial(:)
      ! link and contact forces at the committed step (for trapezoidal work) and at the trial
      real(dp), allocatable :: link_f(:), link_f_trial(:)
      real(dp), allocatable :: con_f(:), con_f_trial(:), con_pen(:), con_pen_trial(:)
      real(dp), allocatable :: con_rate_trial(:), con_rate(:)
      logical, allocatable :: con_on(:)                 !< committed: in contact
      real(dp), allocatable :: con_vin(:), con_vin_trial(:)
      logical, allocatable :: is_penalty(:)
      !> contacts held open for the current step (see the chatter rule of the integrators)
      logical, allocatable :: forced_off(:)
      !> the smooth piece of each law an event-driven integrator holds between located
      !> switches (martello_switching, docs/event-driven.md); BRANCH_FREE and CONTACT_FREE:
      !> the whole law, as the fixed-step methods use it
      integer, allocatable :: link_branch(:), con_branch(:)
      !> stiffness blocks: the recoverable energy ½uᵀku at the committed state, and their
      !> forces (for the works and powers)
      real(dp), allocatable :: blk_e(:)
      type(block_state_t), allocatable :: blk(:)
   end type mech_state_t

   !> One block's elastic force k·u and damping force c·v at the last evaluation (trial),
   !> and the damping force and u at the committed state (trapezoidal damping work).
   type :: block_state_t
      real(dp), allocatable :: f(:), fc(:), fc_n(:), u_n(:)
   end type block_state_t

contains

   !> The committed state of links and contacts at (u, v). stat, message: MARTELLO_ERR_MEMORY
   !> and its line if the state cannot be allocated (absent: the process stops with it).
   subroutine mech_init(m, s, u, v, stat, message)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(out) :: s
      real(dp), intent(in) :: u(0:), v(0:)
      integer, intent(out), optional :: stat
      character(len=*), intent(out), optional :: message
      real(dp), allocatable :: f(:)
      integer :: j, st
      if (present(stat)) stat = MARTELLO_OK
      allocate (s%link_fc(m%nlink), s%link_u(m%nlink), s%link_fc_trial(m%nlink), &
                s%link_f(m%nlink), s%link_f_trial(m%nlink), &
                s%con_f(m%ncontact), s%con_f_trial(m%ncontact), s%con_pen(m%ncontact), &
                s%con_pen_trial(m%ncontact), s%con_rate_trial(m%ncontact), s%con_rate(m%ncontact), &
                s%con_on(m%ncontact), s%con_vin(m%ncontact), s%con_vin_trial(m%ncontact), &
                s%is_penalty(m%ncontact), s%forced_off(m%ncontact), s%link_branch(m%nlink), &
                s%con_branch(m%ncontact), s%blk_e(m%nblock), s%blk(m%nblock), f(0:m%n), stat=st)
      if (st /= 0) then
         call out_of_memory('the element states of the scene', &
                            REAL_BYTES*(5.0_dp*m%nlink + 8.0_dp*m%ncontact + m%nblock + m%n + 1) &
                            + INT_BYTES*(m%nlink + 4.0_dp*m%ncontact) &
                            + storage_size(s%blk)/8*real(m%nblock, dp), FIX_SMALLER_SCENE, stat, message)
         return
      end if
      s%is_penalty = m%con_scheme(1:m%ncontact) == SCHEME_PENALTY
      s%forced_off = .false.
      s%link_branch = BRANCH_FREE; s%con_branch = CONTACT_FREE
      ! The initial state is elastic and unloaded history: the committed force of a bilinear
      ! spring starts on its elastic line k·u0 (clamped into the band by the first step).
      do j = 1, m%nlink
         s%link_u(j) = row_dot(m%lnk, j, u)
         s%link_fc(j) = 0.0_dp
         if (m%link_kind(j) == LINK_SPRING .or. m%link_kind(j) == LINK_BAR .or. &
             m%link_kind(j) == LINK_BILINEAR) s%link_fc(j) = m%link_par(L_STIFF, j)*s%link_u(j)
      end do
      s%con_on = .false.; s%con_vin = 0.0_dp; s%con_rate = 0.0_dp
      do j = 1, m%nblock
         associate (nd => m%block(j)%node)
            s%blk(j)%f = matmul(m%block(j)%k, u(nd))
            s%blk(j)%fc = matmul(m%block(j)%c, v(nd))
            s%blk(j)%fc_n = s%blk(j)%fc
            s%blk(j)%u_n = u(nd)
         end associate
         s%blk_e(j) = block_energy(m, j, u)
      end do
      call internal_forces(m, s, u, v, f)
      call mech_commit(m, s, u)
   end subroutine mech_init

   !> fint(0:n) of links and penalty contacts at (u, v); with jac present, also
   !> jac += ck·K_t + cc·C_t (tangent stiffness and damping), ground rows skipped; with
   !> link_tan, con_tan present, each element's (∂f/∂du, ∂f/∂du̇) (the rates of the element
   !> forces for their located peaks, docs/run-layer.md).
   !> This loop is the cost of a chain step: the linear kinds (spring, bar, dashpot, linear
   !> penalty) are evaluated in line, the others through their constitutive kernels.
   subroutine internal_forces(m, s, u, v, fint, jac, ck, cc, cmat, link_tan, con_tan)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(inout) :: s
      real(dp), intent(in), contiguous :: u(0:), v(0:)
      real(dp), intent(out), contiguous :: fint(0:)
      !> band arrays in the layout of martello_band_matrix (A(i,j) in ab(2kd+1+i−j, j))
      real(dp), intent(inout), contiguous, optional :: jac(:, :)
      real(dp), intent(in), optional :: ck, cc
      real(dp), intent(inout), contiguous, optional :: cmat(:, :)   !< += C_t alone
      real(dp), intent(out), optional :: link_tan(:, :), con_tan(:, :)   !< (2, nlink), (2, ncontact)
      integer :: j, a, b, r
      real(dp) :: du, dv, f, kt, ct, fnew, pen, rate, vin, dfd, dfv
      logical :: tangent

      tangent = present(jac)
      r = 0
      if (tangent) r = (size(jac, 1) - 1)/3*2 + 1
      fint = 0.0_dp
      ! associate: the descriptors are read once, not at every access inside the loop
      associate (kind => m%link_kind, par => m%link_par, &
                 fc => s%link_fc, lu => s%link_u, fc_trial => s%link_fc_trial, f_trial => s%link_f_trial)
         do j = 1, m%nlink
            du = row_dot(m%lnk, j, u); dv = row_dot(m%lnk, j, v)
            select case (kind(j))
            case (LINK_SPRING, LINK_BAR)
               kt = par(L_STIFF, j); ct = 0.0_dp
               f = kt*du; fnew = f
            case (LINK_DASHPOT)
               kt = 0.0_dp; ct = par(L_DAMP, j)
               f = ct*dv; fnew = 0.0_dp
            case default
               if (s%link_branch(j) == BRANCH_FREE) then
                  call link_force(kind(j), par(1, j), du, dv, fc(j), lu(j), f, kt, ct, fnew)
               else
                  call link_force_on_branch(kind(j), par(1, j), s%link_branch(j), du, dv, &
                                            fc(j), lu(j), f, kt, ct, fnew)
               end if
            end select
            fc_trial(j) = fnew
            f_trial(j) = f
            call row_add(m%lnk, j, f, fint)
            if (tangent) call row_stencil(jac, r, m%lnk, j, ck*kt + cc*ct)
            if (present(cmat) .and. ct /= 0.0_dp) call row_stencil(cmat, r, m%lnk, j, ct)
            if (present(link_tan)) link_tan(:, j) = [kt, ct]
         end do
      end associate
      if (present(con_tan)) con_tan = 0.0_dp
      do j = 1, m%ncontact
         if (.not. s%is_penalty(j)) cycle
         pen = row_dot(m%con, j, u) - m%con_gap(j)
         rate = row_dot(m%con, j, v)
         s%con_pen_trial(j) = pen; s%con_rate_trial(j) = rate
         if (s%con_branch(j) == CONTACT_ON .and. m%con_law(j) == LAW_LINEAR) then
            ! held in contact: the linear law extended past delta = 0 (smooth)
            dfd = m%con_par(P_STIFF, j); dfv = 0.0_dp; f = dfd*pen
            s%con_vin_trial(j) = 0.0_dp
         else if (s%con_branch(j) == CONTACT_ON .and. m%con_law(j) == LAW_KELVIN) then
            dfd = m%con_par(P_STIFF, j); dfv = m%con_par(P_DAMPING, j); f = dfd*pen + dfv*rate
            s%con_vin_trial(j) = 0.0_dp
         else if (s%con_branch(j) == CONTACT_OPEN .or. s%con_branch(j) == CONTACT_CUT) then
            f = 0.0_dp; dfd = 0.0_dp; dfv = 0.0_dp
            ! the onset speed a commit past the located onset keeps: the rate there, the
            ! relative speed at the instant of impact of the Hunt–Crossley family's
            ! χ = a/δ̇⁽⁻⁾ (Hunt & Crossley 1975, Lankarani & Nikravesh 1990, Flores et al.
            ! 2011; docs/problems.md P5), not the larger of it and the previous commit's
            s%con_vin_trial(j) = s%con_vin(j)
            if (.not. s%con_on(j)) s%con_vin_trial(j) = max(rate, ONSET_SPEED_FLOOR)
         else if (pen > 0.0_dp .and. .not. s%forced_off(j)) then
            ! onset speed of a step that closes the gap (the fixed steps): the rate where δ
            ! crosses 0, interpolated between the committed (free-side) state and the trial
            ! one — second order where either end alone is first order once the approach is
            ! accelerated (the springs of P7's two oscillators), and exact for a free impact
            ! to the contact's own O(h^(n+1)) pull on the rate after the touch
            vin = s%con_vin(j)
            if (.not. s%con_on(j)) vin = onset_speed(s%con_pen(j), s%con_rate(j), pen, rate)
            s%con_vin_trial(j) = vin
            if (m%con_law(j) == LAW_LINEAR) then
               dfd = m%con_par(P_STIFF, j); dfv = 0.0_dp; f = dfd*pen
            else
               call contact_force(m%con_law(j), m%con_par(1, j), m%con_mstar(j), pen, rate, vin, &
                                  f, dfd, dfv)
            end if
         else
            f = 0.0_dp; dfd = 0.0_dp; dfv = 0.0_dp
            s%con_vin_trial(j) = 0.0_dp
         end if
         s%con_f_trial(j) = f
         if (present(con_tan)) con_tan(:, j) = [dfd, dfv]
         call row_add(m%con, j, f, fint)
         if (tangent .and. (dfd /= 0.0_dp .or. dfv /= 0.0_dp)) &
            call row_stencil(jac, r, m%con, j, ck*dfd + cc*dfv)
         if (present(cmat) .and. dfv /= 0.0_dp) call row_stencil(cmat, r, m%con, j, dfv)
      end do
      do j = 1, m%nblock
         associate (nd => m%block(j)%node, kb => m%block(j)%k, cb => m%block(j)%c, &
                    fb => s%blk(j)%f, fcb => s%blk(j)%fc, damped => m%block(j)%damped)
            fb = matmul(kb, u(nd))
            fint(nd) = fint(nd) + fb
            if (damped) then
               fcb = matmul(cb, v(nd))
               fint(nd) = fint(nd) + fcb
            end if
            ! band layout A(i,j) in ab(r+i−j, j); model_bandwidth covers the block's span
            if (tangent) then
               do b = 1, size(nd)
                  do a = 1, size(nd)
                     jac(r + nd(a) - nd(b), nd(b)) = jac(r + nd(a) - nd(b), nd(b)) + ck*kb(a, b)
                     if (damped) jac(r + nd(a) - nd(b), nd(b)) = &
                        jac(r + nd(a) - nd(b), nd(b)) + cc*cb(a, b)
                  end do
               end do
            end if
            if (present(cmat) .and. damped) then
               do b = 1, size(nd)
                  do a = 1, size(nd)
                     cmat(r + nd(a) - nd(b), nd(b)) = cmat(r + nd(a) - nd(b), nd(b)) + cb(a, b)
                  end do
               end do
            end if
         end associate
      end do
      fint(0) = 0.0_dp
   end subroutine internal_forces

   !> The approach speed where δ crosses 0 between a committed state (δ0 < 0, rate r0) and a
   !> trial one (δ1 > 0, rate r1), linear in the fraction δ0/(δ0 − δ1); a contact first seen
   !> already closed or opening (grazing, a step that lands inside) takes the larger rate,
   !> and never less than ONSET_SPEED_FLOOR (χ = a/v_in).
   pure function onset_speed(d0, r0, d1, r1) result(v)
      real(dp), intent(in) :: d0, r0, d1, r1
      real(dp) :: v
      if (d0 < 0.0_dp .and. d1 > d0) then
         v = r0 + (r1 - r0)*(-d0/(d1 - d0))
      else
         v = max(r0, r1)
      end if
      v = max(v, ONSET_SPEED_FLOOR)
   end function onset_speed

   !> Accept the trial state of the last internal_forces call; optionally return the
   !> trapezoidal work of the elements over the step just ended, split into damping links,
   !> other links and contacts (the energy balance of the integrators).
   subroutine mech_commit(m, s, u, w_damp, w_links, w_contact)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(inout) :: s
      real(dp), intent(in) :: u(0:)
      real(dp), intent(out), optional :: w_damp, w_links, w_contact
      integer :: j
      real(dp) :: du, w
      if (present(w_damp)) then
         w_damp = 0.0_dp; w_links = 0.0_dp; w_contact = 0.0_dp
      end if
      do j = 1, m%nlink
         du = row_dot(m%lnk, j, u)
         if (present(w_damp)) then
            w = 0.5_dp*(s%link_f(j) + s%link_f_trial(j))*(du - s%link_u(j))
            if (is_damper(m%link_kind(j))) then
               w_damp = w_damp + w
            else
               w_links = w_links + w
            end if
         end if
         s%link_fc(j) = s%link_fc_trial(j)
         s%link_u(j) = du
      end do
      ! a linear symmetric block: the trapezoidal work ½(k uₙ + k uₙ₊₁)·(uₙ₊₁ − uₙ) is exactly
      ! the change of ½uᵀku
      do j = 1, m%nblock
         w = block_energy(m, j, u)
         associate (bs => s%blk(j), nd => m%block(j)%node)
            if (present(w_damp)) then
               w_links = w_links + (w - s%blk_e(j))
               if (m%block(j)%damped) w_damp = w_damp + &
                  0.5_dp*dot_product(bs%fc_n + bs%fc, u(nd) - bs%u_n)
            end if
            if (m%block(j)%damped) bs%fc_n = bs%fc
            bs%u_n = u(nd)
         end associate
         s%blk_e(j) = w
      end do
      if (present(w_damp)) then
         do j = 1, m%ncontact
            if (s%is_penalty(j)) w_contact = w_contact + &
               0.5_dp*(s%con_f(j) + s%con_f_trial(j))*(s%con_pen_trial(j) - s%con_pen(j))
         end do
      end if
      ! committed ← trial by swapping the arrays, not copying them (a chain step is
      ! memory-bound); the stale trial arrays are rewritten by the next evaluation
      call swap(s%link_f, s%link_f_trial)
      call swap(s%con_f, s%con_f_trial)
      s%con_pen = s%con_pen_trial      ! kept: the activation test below reads the trial
      s%con_on = s%con_pen_trial > 0.0_dp .and. s%is_penalty .and. .not. s%forced_off
      s%forced_off = .false.
      call swap(s%con_vin, s%con_vin_trial)
      s%con_rate = s%con_rate_trial
   end subroutine mech_commit

   !> The power the elements absorb at the trial state of the last internal_forces call,
   !> Σ f·(v_a − v_b), split as mech_commit's works (dampers, other links, penalty contacts):
   !> the integrands of the works for integrators that integrate them along their own
   !> solution (the adaptive C integrators, docs/run-layer.md).
   pure subroutine element_power(m, s, v, p_damp, p_links, p_contact)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: s
      real(dp), intent(in) :: v(0:)
      real(dp), intent(out) :: p_damp, p_links, p_contact
      integer :: j
      real(dp) :: p
      p_damp = 0.0_dp; p_links = 0.0_dp; p_contact = 0.0_dp
      do j = 1, m%nlink
         p = s%link_f_trial(j)*row_dot(m%lnk, j, v)
         if (is_damper(m%link_kind(j))) then
            p_damp = p_damp + p
         else
            p_links = p_links + p
         end if
      end do
      do j = 1, m%ncontact
         if (s%is_penalty(j)) p_contact = p_contact + s%con_f_trial(j)*s%con_rate_trial(j)
      end do
      do j = 1, m%nblock
         p_links = p_links + dot_product(s%blk(j)%f, v(m%block(j)%node))
         if (m%block(j)%damped) p_damp = p_damp + dot_product(s%blk(j)%fc, v(m%block(j)%node))
      end do
   end subroutine element_power

   !> ½ uᵀ k u of stiffness block j.
   pure real(dp) function block_energy(m, j, u) result(e)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      real(dp), intent(in) :: u(0:)
      real(dp) :: x(size(m%block(j)%node))
      ! the block's displacements as an array of its own (a vector subscript inside matmul
      ! makes gfortran warn of an uninitialised temporary's descriptor)
      x = u(m%block(j)%node)
      e = 0.5_dp*dot_product(x, matmul(m%block(j)%k, x))
   end function block_energy

   !> Links whose work is damping (no recoverable energy): the energy balance's split.
   pure logical function is_damper(kind)
      integer, intent(in) :: kind
      is_damper = kind == LINK_DASHPOT .or. kind == LINK_FLUID_DAMPER
   end function is_damper

   !> x ↔ y, the arrays moved, not copied (a committed state and its trial)
   subroutine swap(x, y)
      real(dp), allocatable, intent(inout) :: x(:), y(:)
      real(dp), allocatable :: tmp(:)
      call move_alloc(x, tmp); call move_alloc(y, x); call move_alloc(tmp, y)
   end subroutine swap

   !> The acceleration every mass is loaded with at t: gravity − ü_g (relative coordinates).
   real(dp) function uniform_acceleration(m, t) result(acc)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      acc = m%gravity
      if (m%ground_accel%kind /= TF_NONE) acc = acc - tf_value(m%ground_accel, t)
   end function uniform_acceleration

   !> The first time after t where a load of the scene has a kink (tf_next_breakpoint: a
   !> window's start or end, a table's sample), or huge().
   pure function load_breakpoint(m, t) result(tb)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: t
      real(dp) :: tb
      integer :: j
      tb = huge(1.0_dp)
      if (m%ground_accel%kind /= TF_NONE) tb = tf_next_breakpoint(m%ground_accel, t)
      do j = 1, m%nforce
         tb = min(tb, tf_next_breakpoint(m%force_fn(j), t))
      end do
   end function load_breakpoint

   !> The shortest period of the loads' harmonic terms (tf_period), or huge().
   pure function load_period(m) result(p)
      type(model_t), intent(in) :: m
      real(dp) :: p
      integer :: j
      p = huge(1.0_dp)
      if (m%ground_accel%kind /= TF_NONE) p = tf_period(m%ground_accel)
      do j = 1, m%nforce
         p = min(p, tf_period(m%force_fn(j)))
      end do
   end function load_period

   !> Gravity on M·1, nodal forces, and −M·1·ü_g (relative coordinates), at time t.
   subroutine external_forces(m, mass_row_sum, t, fext)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: mass_row_sum(0:), t
      real(dp), intent(out) :: fext(0:)
      integer :: j
      real(dp) :: acc
      acc = uniform_acceleration(m, t)
      fext = acc*mass_row_sum
      do j = 1, m%nforce
         fext(m%force_node(j)) = fext(m%force_node(j)) + tf_value(m%force_fn(j), t)
      end do
      fext(0) = 0.0_dp
   end subroutine external_forces

   !> Recoverable (elastic) energy of links and of penalty contacts at the committed state.
   subroutine recoverable_energy(m, s, u, e_links, e_contacts)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: s
      real(dp), intent(in) :: u(0:)
      real(dp), intent(out) :: e_links, e_contacts
      integer :: j
      real(dp) :: du, eb
      e_links = 0.0_dp; e_contacts = 0.0_dp
      do j = 1, m%nlink
         du = row_dot(m%lnk, j, u)
         select case (m%link_kind(j))
         case (LINK_SPRING, LINK_BAR)
            e_links = e_links + 0.5_dp*m%link_par(L_STIFF, j)*du**2
         case (LINK_BILINEAR)
            call bilinear_energy(m%link_par(L_STIFF, j), m%link_par(L_YIELD, j), &
                                 m%link_par(L_HARDENING, j), s%link_fc(j), du, eb)
            e_links = e_links + eb
         end select
      end do
      do j = 1, m%nblock
         e_links = e_links + block_energy(m, j, u)
      end do
      do j = 1, m%ncontact
         if (s%is_penalty(j)) e_contacts = e_contacts + &
            contact_elastic_energy(m%con_law(j), m%con_par(:, j), max(s%con_pen(j), 0.0_dp))
      end do
   end subroutine recoverable_energy

   !> y = M x for the lumped diagonal plus the consistent-mass couplings.
   pure subroutine mass_times(m, x, y)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: x(0:)
      real(dp), intent(out) :: y(0:)
      integer :: j
      y(1:) = m%mass*x(1:)
      y(0) = 0.0_dp
      do j = 1, m%ncoupling
         y(m%mc_a(j)) = y(m%mc_a(j)) + m%mc_value(j)*x(m%mc_b(j))
         y(m%mc_b(j)) = y(m%mc_b(j)) + m%mc_value(j)*x(m%mc_a(j))
      end do
   end subroutine mass_times

   !> M·ι (0:n, ground 0): what the uniform acceleration (gravity − ü_g) loads, ι the
   !> model's influence vector (1 for every node of a 1D scene; Chopra §9.4). work: 0:n.
   pure subroutine load_pattern(m, work, mrow)
      type(model_t), intent(in) :: m
      real(dp), intent(out) :: work(0:), mrow(0:)
      work = 1.0_dp; work(0) = 0.0_dp
      if (allocated(m%influence)) then
         if (size(m%influence) > 0) work(1:m%n) = m%influence
      end if
      call mass_times(m, work, mrow)
   end subroutine load_pattern

   !> jac += c·M (band).
   pure subroutine assemble_mass(m, c, jac)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: c
      type(band_t), intent(inout) :: jac
      integer :: i, j, r
      r = 2*jac%kd + 1
      do i = 1, m%n
         jac%ab(r, i) = jac%ab(r, i) + c*m%mass(i)
      end do
      do j = 1, m%ncoupling
         call band_add(jac, m%mc_a(j), m%mc_b(j), c*m%mc_value(j))
         call band_add(jac, m%mc_b(j), m%mc_a(j), c*m%mc_value(j))
      end do
   end subroutine assemble_mass
   !> Trapezoidal work of the external forces over a step, ½(f_n + f_{n+1})·(u_{n+1} − u_n),
   !> on the free nodes.
   pure real(dp) function external_work(m, fext_n, fext, un, u) result(w)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: fext_n(0:), fext(0:), un(0:), u(0:)
      integer :: i
      w = 0.0_dp
      do i = 1, m%n
         if (.not. m%fixed(i)) w = w + 0.5_dp*(fext_n(i) + fext(i))*(u(i) - un(i))
      end do
   end function external_work
   !> ½ vᵀ M v (work: scratch of length 0:n for M v).
   real(dp) function kinetic_energy(m, v, work) result(e)
      type(model_t), intent(in) :: m
      real(dp), intent(in) :: v(0:)
      real(dp), intent(out) :: work(0:)
      call mass_times(m, v, work)
      e = 0.5_dp*dot_product(v(1:m%n), work(1:m%n))
   end function kinetic_energy
end module martello_assembly
