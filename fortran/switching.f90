!> The switching surfaces of a scene's laws for event-driven integrators (docs/event-driven.md,
!> switching surfaces): each law that is only piecewise smooth — the bilinear spring (yield,
!> unloading), the fluid damper (its regularisation speed, or dv = 0 without one), the
!> clipped Kelvin contact (its tension cut-off) and every penalty contact (onset and
!> separation, located by the integrator on the gap) — is held on one smooth branch
!> (mech_state_t%link_branch, con_branch) between located switches. The switches of the
!> branches held are affine in the relative motion of two nodes,
!>
!>    g = alpha (u_a - u_b) + beta (v_a - v_b) + gamma,   g > 0: the branch is left,
!>
!> with coefficients fixed between commits, so the integrator evaluates them on any state,
!> interpolant or re-integrated stage without calling the kernels.
module martello_switching
   use martello_kinds, only: dp
   use martello_model, only: model_t
   use martello_element_rows, only: row_dot
   use martello_assembly, only: mech_state_t, CONTACT_FREE, CONTACT_OPEN, CONTACT_ON, CONTACT_CUT
   use martello_links, only: LINK_BILINEAR, LINK_FLUID_DAMPER, L_STIFF, L_DAMP, L_YIELD, &
      L_HARDENING, L_ALPHA, L_VREG, BRANCH_FREE, BRANCH_ELASTIC, BRANCH_UPPER, BRANCH_LOWER, &
      BRANCH_LINEAR, BRANCH_POWER_POS, BRANCH_POWER_NEG
   use martello_contact_laws, only: LAW_KELVIN, LAW_LINEAR, LAW_HERTZ, LAW_HUNT_CROSSLEY, &
      LAW_LANKARANI_NIKRAVESH, LAW_FLORES, LAW_GONTHIER, LAW_HERTZDAMP, P_STIFF, P_DAMPING, P_CLIP, &
      law_rate_bounded
   implicit none
   private
   public :: switch_count, switching_choose, switching_functions, force_continuous, stepped_across
   public :: ACROSS_NONE, ACROSS_CONTINUOUS, ACROSS_RATE_BOUNDED

   !> The penalty contacts an integrator steps across (left whole, not held on branches):
   !> none; those whose force is continuous at their switches (force_continuous: CVODE, IDA);
   !> only those whose force's rate is bounded there too (law_rate_bounded: ARKODE, whose
   !> embedded error estimate does not bound a step across an unbounded second derivative;
   !> docs/sundials-ode.md, events inside the steps). Values shared with the C door.
   integer, parameter :: ACROSS_NONE = 0, ACROSS_CONTINUOUS = 1, ACROSS_RATE_BOUNDED = 2

contains

   !> Two slots per link (the two sides of a band) and one per contact.
   pure integer function switch_count(m)
      type(model_t), intent(in) :: m
      switch_count = 2*m%nlink + m%ncontact
   end function switch_count

   !> After a commit at the state (u, v) (0:n, 0 = ground): every branch whose switch is past
   !> (g > 0) moves to the next branch (a bilinear one only while loading outward);
   !> CONTACT_FREE and BRANCH_FREE are chosen from the state. A bilinear force left outside its band by the located crossing (by at most
   !> k |dv| event_tol) is put back on the band's edge. across (ACROSS_*, default none): the
   !> contacts stepped across (stepped_across) are not held: they stay the whole law, whose
   !> kinks the integrator's error control takes (docs/sundials-ode.md, events inside the steps).
   subroutine switching_choose(m, s, u, v, across)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(inout) :: s
      real(dp), intent(in) :: u(0:), v(0:)
      integer, intent(in), optional :: across
      integer :: laws
      integer :: j
      real(dp) :: du, dv, k, rho, r, back, fp, pen, g(2)
      integer :: el(2)
      real(dp) :: al(2), be(2), ga(2)
      laws = ACROSS_NONE
      if (present(across)) laws = across
      do j = 1, m%nlink
         du = row_dot(m%lnk, j, u); dv = row_dot(m%lnk, j, v)
         select case (m%link_kind(j))
         case (LINK_BILINEAR)
            k = m%link_par(L_STIFF, j); rho = m%link_par(L_HARDENING, j)
            if (rho >= 1.0_dp) cycle
            r = (1.0_dp - rho)*m%link_par(L_YIELD, j)
            back = rho*k*du
            fp = s%link_fc(j) - back
            if (s%link_branch(j) == BRANCH_FREE) then
               s%link_branch(j) = BRANCH_ELASTIC
               if (fp >= r .and. dv > 0.0_dp) s%link_branch(j) = BRANCH_UPPER
               if (fp <= -r .and. dv < 0.0_dp) s%link_branch(j) = BRANCH_LOWER
            else
               call link_switch(m, s, j, el, al, be, ga)
               g = al*du + be*dv + ga
               select case (s%link_branch(j))
               case (BRANCH_ELASTIC)
                  ! yielding needs loading: a surface reached at the turning point (dv = 0,
                  ! grazing) leaves the link elastic on the band's edge
                  if (g(1) > 0.0_dp .and. dv > 0.0_dp) s%link_branch(j) = BRANCH_UPPER
                  if (g(2) > 0.0_dp .and. dv < 0.0_dp) s%link_branch(j) = BRANCH_LOWER
               case (BRANCH_UPPER, BRANCH_LOWER)
                  if (g(1) > 0.0_dp) s%link_branch(j) = BRANCH_ELASTIC
               end select
            end if
            ! a force past the band's edge (the crossing located to event_tol) returns to it
            s%link_fc(j) = min(max(s%link_fc(j), back - r), back + r)
         case (LINK_FLUID_DAMPER)
            if (m%link_par(L_ALPHA, j) == 1.0_dp) cycle
            if (abs(dv) < m%link_par(L_VREG, j)) then
               s%link_branch(j) = BRANCH_LINEAR
            else if (s%link_branch(j) == BRANCH_POWER_POS .and. m%link_par(L_VREG, j) <= 0.0_dp &
                     .and. dv == 0.0_dp) then
               cycle                          ! at rest on dv = 0: keep the side
            else
               s%link_branch(j) = merge(BRANCH_POWER_POS, BRANCH_POWER_NEG, dv >= 0.0_dp)
            end if
         end select
      end do
      do j = 1, m%ncontact
         if (.not. s%is_penalty(j)) cycle
         if (stepped_across(m, j, laws)) then
            s%con_branch(j) = CONTACT_FREE
            cycle
         end if
         pen = row_dot(m%con, j, u) - m%con_gap(j)
         dv = row_dot(m%con, j, v)
         if (.not. (pen > 0.0_dp)) then
            s%con_branch(j) = CONTACT_OPEN
         else if (kelvin_clipped(m, j)) then
            if (m%con_par(P_STIFF, j)*pen + m%con_par(P_DAMPING, j)*dv > 0.0_dp) then
               s%con_branch(j) = CONTACT_ON
            else
               s%con_branch(j) = CONTACT_CUT
            end if
         else
            s%con_branch(j) = CONTACT_ON
         end if
      end do
   end subroutine switching_choose

   !> The switches of the branches held: slots 2j-1, 2j of link j, 2 nlink + j of contact j.
   !> A switch is g = alpha d + beta d' + gamma on the deformation d of its element el (0-based
   !> for the C door: link j is el = j − 1, contact j el = nlink + j − 1, martello_element_rows;
   !> −1 none); an unused slot has alpha = beta = 0, gamma = -1 (never crossed).
   subroutine switching_functions(m, s, el, alpha, beta, gamma)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: s
      integer, intent(out) :: el(:)
      real(dp), intent(out) :: alpha(:), beta(:), gamma(:)
      integer :: j, i
      el = -1; alpha = 0.0_dp; beta = 0.0_dp; gamma = -1.0_dp
      do j = 1, m%nlink
         call link_switch(m, s, j, el(2*j - 1:2*j), alpha(2*j - 1:2*j), &
                          beta(2*j - 1:2*j), gamma(2*j - 1:2*j))
      end do
      do j = 1, m%ncontact
         i = 2*m%nlink + j
         if (.not. (s%is_penalty(j) .and. kelvin_clipped(m, j))) cycle
         if (s%con_branch(j) /= CONTACT_ON .and. s%con_branch(j) /= CONTACT_CUT) cycle
         ! the Kelvin force k delta + c delta' over k: its sign change is the cut-off
         el(i) = m%nlink + j - 1
         alpha(i) = 1.0_dp
         beta(i) = m%con_par(P_DAMPING, j)/m%con_par(P_STIFF, j)
         gamma(i) = -m%con_gap(j)
         if (s%con_branch(j) == CONTACT_ON) then   ! leaves when the force turns tensile
            alpha(i) = -alpha(i); beta(i) = -beta(i); gamma(i) = -gamma(i)
         end if
      end do
   end subroutine switching_functions

   !> The two switch slots of link j on its branch (scaled to metres or metres per second).
   pure subroutine link_switch(m, s, j, el, alpha, beta, gamma)
      type(model_t), intent(in) :: m
      type(mech_state_t), intent(in) :: s
      integer, intent(in) :: j
      integer, intent(out) :: el(2)
      real(dp), intent(out) :: alpha(2), beta(2), gamma(2)
      real(dp) :: k, rho, r, c0, vreg
      el = j - 1
      alpha = 0.0_dp; beta = 0.0_dp; gamma = -1.0_dp
      select case (s%link_branch(j))
      case (BRANCH_ELASTIC)
         ! f_n + k (du - u_n) - rho k du = +-(1 - rho) F_y, over k
         k = m%link_par(L_STIFF, j); rho = m%link_par(L_HARDENING, j)
         r = (1.0_dp - rho)*m%link_par(L_YIELD, j)
         c0 = (s%link_fc(j) - k*s%link_u(j))/k
         alpha = [1.0_dp - rho, -(1.0_dp - rho)]
         gamma = [c0 - r/k, -c0 - r/k]
      case (BRANCH_UPPER)
         beta(1) = -1.0_dp; gamma(1) = 0.0_dp        ! unloading: dv < 0
      case (BRANCH_LOWER)
         beta(1) = 1.0_dp; gamma(1) = 0.0_dp
      case (BRANCH_LINEAR)
         vreg = m%link_par(L_VREG, j)
         beta = [1.0_dp, -1.0_dp]; gamma = -vreg       ! |dv| reaches v_reg
      case (BRANCH_POWER_POS)
         beta(1) = -1.0_dp; gamma(1) = m%link_par(L_VREG, j)
      case (BRANCH_POWER_NEG)
         beta(1) = 1.0_dp; gamma(1) = m%link_par(L_VREG, j)
      end select
   end subroutine link_switch

   !> Whether penalty contact j's force is continuous where it starts and ends (F = 0 at
   !> delta = 0 both ways, and no other jump): linear, Hertz and the Hunt-Crossley family (whose
   !> damping factor 1 + chi delta' is clipped at 0). Kelvin jumps by c delta' at its onset (and,
   !> unclipped, at its separation); Jankowski's damping grows as delta^(1/4), a force continuous
   !> at the onset but with an unbounded rate that no error control takes in one step.
   pure logical function force_continuous(m, j)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      select case (m%con_law(j))
      case (LAW_LINEAR, LAW_HERTZ, LAW_HUNT_CROSSLEY, LAW_LANKARANI_NIKRAVESH, LAW_FLORES, &
            LAW_GONTHIER, LAW_HERTZDAMP)
         force_continuous = .true.
      case default
         force_continuous = .false.
      end select
   end function force_continuous

   !> Whether penalty contact j is stepped across under the class laws (ACROSS_*).
   pure logical function stepped_across(m, j, laws)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j, laws
      select case (laws)
      case (ACROSS_CONTINUOUS)
         stepped_across = force_continuous(m, j)
      case (ACROSS_RATE_BOUNDED)
         stepped_across = force_continuous(m, j) .and. law_rate_bounded(m%con_law(j), m%con_par(:, j))
      case default
         stepped_across = .false.
      end select
   end function stepped_across

   pure logical function kelvin_clipped(m, j)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      kelvin_clipped = m%con_law(j) == LAW_KELVIN .and. m%con_par(P_CLIP, j) > 0.5_dp
   end function kelvin_clipped
end module martello_switching
