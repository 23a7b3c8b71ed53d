!> Two-node connectors (node b may be ground): springs, dashpots, bilinear hysteretic springs,
!> fluid-viscous dampers and axial bars (docs/problems.md P6, P7, P8).
!>
!> Conventions: du = u_a - u_b (elongation), dv = its rate. f = f(du, dv) is positive when
!> the link is stretched; node a receives -f and node b receives +f. k_tan = df/d(du),
!> c_tan = df/d(dv). Each kind reads only its own slots of par(NPAR_LINK) (see link_force);
!> damping in parallel with a spring is a second link. Invalid kinds or parameters give NaN.
module martello_links
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use martello_kinds, only: dp
   implicit none
   private

   public :: LINK_SPRING, LINK_DASHPOT, LINK_BILINEAR, LINK_FLUID_DAMPER, LINK_BAR
   public :: NPAR_LINK, L_STIFF, L_DAMP, L_YIELD, L_HARDENING, L_ALPHA, L_VREG
   public :: bilinear_return_map, bilinear_energy, fluid_damper_force, link_force
   public :: link_is_known, link_force_on_branch
   public :: BRANCH_FREE, BRANCH_ELASTIC, BRANCH_UPPER, BRANCH_LOWER, BRANCH_LINEAR, &
      BRANCH_POWER_POS, BRANCH_POWER_NEG

   ! Link kinds: values are frozen, the C and Python layers use the same integers.
   integer, parameter :: LINK_SPRING = 1
   integer, parameter :: LINK_DASHPOT = 2
   integer, parameter :: LINK_BILINEAR = 3
   integer, parameter :: LINK_FLUID_DAMPER = 4
   integer, parameter :: LINK_BAR = 5

   integer, parameter :: NPAR_LINK = 6
   integer, parameter :: L_STIFF = 1      ! k [N/m]; for LINK_BAR the caller stores EA/L
   integer, parameter :: L_DAMP = 2       ! c: [N s/m] dashpot, [N (s/m)^alpha] fluid damper
   integer, parameter :: L_YIELD = 3      ! F_y > 0
   integer, parameter :: L_HARDENING = 4  ! rho in [0, 1)
   integer, parameter :: L_ALPHA = 5      ! damper exponent alpha in (0, 2]
   integer, parameter :: L_VREG = 6       ! damper regularisation speed >= 0

   ! Branches of a link's law (docs/event-driven.md, switching surfaces): an event-driven
   ! integrator fixes the smooth piece of the law between two located switches, so no
   ! Runge–Kutta stage evaluates a kink. BRANCH_FREE: the law as a whole (fixed-step methods).
   integer, parameter :: BRANCH_FREE = 0
   integer, parameter :: BRANCH_ELASTIC = 1     ! bilinear inside the band: f_n + k (du - u_n)
   integer, parameter :: BRANCH_UPPER = 2       ! bilinear on rho k du + (1 - rho) F_y
   integer, parameter :: BRANCH_LOWER = 3       ! bilinear on rho k du - (1 - rho) F_y
   integer, parameter :: BRANCH_LINEAR = 4      ! fluid damper below v_reg: the secant line
   integer, parameter :: BRANCH_POWER_POS = 5   ! fluid damper c dv^alpha, dv > 0
   integer, parameter :: BRANCH_POWER_NEG = 6   ! fluid damper -c (-dv)^alpha, dv < 0

contains

   !> link_force on a fixed branch of a bilinear spring or a fluid damper: the smooth
   !> extension of that piece of the law beyond its switching surface (where a stage of a
   !> one-step method may land before the switch is located). Other kinds and BRANCH_FREE:
   !> link_force.
   pure subroutine link_force_on_branch(kind, par, branch, du, dv, state_f, state_u, f, k_tan, &
                                        c_tan, f_committed_new)
      integer, intent(in) :: kind, branch
      real(dp), intent(in) :: par(NPAR_LINK)
      real(dp), intent(in) :: du, dv, state_f, state_u
      real(dp), intent(out) :: f, k_tan, c_tan, f_committed_new
      real(dp) :: k, rho, r, s
      k_tan = 0.0_dp
      c_tan = 0.0_dp
      select case (branch)
      case (BRANCH_ELASTIC, BRANCH_UPPER, BRANCH_LOWER)
         k = par(L_STIFF); rho = par(L_HARDENING); r = (1.0_dp - rho)*par(L_YIELD)
         if (branch == BRANCH_ELASTIC) then
            f = state_f + k*(du - state_u)
            k_tan = k
         else
            f = rho*k*du + merge(r, -r, branch == BRANCH_UPPER)
            k_tan = rho*k
         end if
         f_committed_new = f
      case (BRANCH_LINEAR)
         c_tan = par(L_DAMP)*par(L_VREG)**(par(L_ALPHA) - 1.0_dp)
         f = c_tan*dv
         f_committed_new = 0.0_dp
      case (BRANCH_POWER_POS, BRANCH_POWER_NEG)
         s = merge(1.0_dp, -1.0_dp, branch == BRANCH_POWER_POS)
         f = s*par(L_DAMP)*max(s*dv, 0.0_dp)**par(L_ALPHA)
         c_tan = par(L_DAMP)*par(L_ALPHA)*max(s*dv, tiny(1.0_dp))**(par(L_ALPHA) - 1.0_dp)
         f_committed_new = 0.0_dp
      case default
         call link_force(kind, par, du, dv, state_f, state_u, f, k_tan, c_tan, f_committed_new)
      end select
   end subroutine link_force_on_branch

   !> Bilinear spring with kinematic hardening (docs/problems.md P6): a trial step from the
   !> committed state (f_n, u_n) to the elongation u_new. The force is bounded by the lines
   !> rho k u +- (1 - rho) F_y, so the return map is a clamp of the elastic predictor;
   !> the consistent tangent is k if the clamp was inactive, rho k otherwise.
   !> Nothing is stored: the caller commits (f_new, u_new) when the step is accepted.
   !> Elemental (as are bilinear_energy and fluid_damper_force): a chain can update all its
   !> links in one call.
   elemental subroutine bilinear_return_map(k, fy, rho, f_n, u_n, u_new, f_new, tangent, yielding)
      real(dp), intent(in) :: k, fy, rho, f_n, u_n, u_new
      real(dp), intent(out) :: f_new, tangent
      logical, intent(out) :: yielding
      real(dp) :: f_trial, back, r

      yielding = .false.
      if (.not. (k > 0.0_dp .and. fy > 0.0_dp .and. rho >= 0.0_dp .and. rho <= 1.0_dp)) then
         f_new = nan()
         tangent = f_new
         return
      end if
      f_trial = f_n + k*(u_new - u_n)
      back = rho*k*u_new            ! centre of the elastic band (back force)
      r = (1.0_dp - rho)*fy         ! half-width of the band
      if (f_trial > back + r) then
         f_new = back + r
         yielding = .true.
      else if (f_trial < back - r) then
         f_new = back - r
         yielding = .true.
      else
         f_new = f_trial
      end if
      if (yielding) then
         tangent = rho*k
      else
         tangent = k
      end if
   end subroutine bilinear_return_map

   !> Recoverable (elastic) energy of a bilinear state (f, u): an elastic spring rho k in
   !> parallel with an elastic-perfectly-plastic spring (1 - rho) k of yield (1 - rho) F_y,
   !> e = rho k u^2/2 + F_p^2/(2 (1 - rho) k), F_p = f - rho k u (rho = 1: purely elastic).
   !> fy is used to reject states outside the band |F_p| <= (1 - rho) F_y (NaN), which no
   !> return map can produce; the allowance covers the round-off of recomputing F_p.
   elemental subroutine bilinear_energy(k, fy, rho, f, u, e_recoverable)
      real(dp), intent(in) :: k, fy, rho, f, u
      real(dp), intent(out) :: e_recoverable
      real(dp) :: fp, back

      if (.not. (k > 0.0_dp .and. fy > 0.0_dp .and. rho >= 0.0_dp .and. rho <= 1.0_dp)) then
         e_recoverable = nan()
         return
      end if
      back = rho*k*u
      e_recoverable = 0.5_dp*back*u
      if (rho >= 1.0_dp) return
      fp = f - back
      if (abs(fp) > (1.0_dp - rho)*fy + 8.0_dp*epsilon(1.0_dp)*(abs(f) + abs(back) + fy)) then
         e_recoverable = nan()
         return
      end if
      e_recoverable = e_recoverable + 0.5_dp*fp*fp/((1.0_dp - rho)*k)
   end subroutine bilinear_energy

   !> Fluid-viscous damper F = c sign(v) |v|^alpha (seed §5, docs/problems.md P8).
   !> For alpha < 1 the tangent c alpha |v|^(alpha-1) is infinite at v = 0 and Newton
   !> iterations break down, so for |v| < v_reg the law is replaced by the secant line
   !> F = c v_reg^(alpha-1) v: continuous at |v| = v_reg, the slope jumps by the factor alpha.
   !> v_reg = 0 disables the regularisation: fine for alpha >= 1; for alpha < 1 the tangent
   !> at v = 0 is returned as +Inf.
   elemental subroutine fluid_damper_force(c, alpha, v_reg, v, f, df_dv)
      real(dp), intent(in) :: c, alpha, v_reg, v
      real(dp), intent(out) :: f, df_dv
      real(dp) :: av, slope

      if (.not. (alpha > 0.0_dp .and. v_reg >= 0.0_dp)) then
         f = nan()
         df_dv = f
         return
      end if
      av = abs(v)
      if (av < v_reg) then
         slope = c*v_reg**(alpha - 1.0_dp)
         f = slope*v
         df_dv = slope
      else if (av <= 0.0_dp) then     ! v = 0, only reached with v_reg = 0
         f = 0.0_dp
         if (alpha < 1.0_dp) then
            df_dv = ieee_value(1.0_dp, ieee_positive_inf)
         else if (alpha > 1.0_dp) then
            df_dv = 0.0_dp
         else
            df_dv = c
         end if
      else
         f = sign(c*av**alpha, v)
         df_dv = c*alpha*av**(alpha - 1.0_dp)
      end if
   end subroutine fluid_damper_force

   !> Force of one link and its tangents, dispatched on kind:
   !>  LINK_SPRING       f = k du                         (par(L_STIFF))
   !>  LINK_BAR          f = k du with k = EA/L           (par(L_STIFF); mass handled elsewhere)
   !>  LINK_DASHPOT      f = c dv                         (par(L_DAMP))
   !>  LINK_BILINEAR     return map from the committed (state_f, state_u)
   !>                                                     (par(L_STIFF, L_YIELD, L_HARDENING))
   !>  LINK_FLUID_DAMPER fluid_damper_force               (par(L_DAMP, L_ALPHA, L_VREG))
   !> f_committed_new is the rate-independent part of f (the bilinear trial force, k du for
   !> springs and bars, 0 for dampers): on acceptance the caller commits
   !> state_f = f_committed_new, state_u = du for every link alike.
   pure subroutine link_force(kind, par, du, dv, state_f, state_u, f, k_tan, c_tan, f_committed_new)
      integer, intent(in) :: kind
      real(dp), intent(in) :: par(NPAR_LINK)
      real(dp), intent(in) :: du, dv, state_f, state_u
      real(dp), intent(out) :: f, k_tan, c_tan, f_committed_new
      logical :: yielding

      k_tan = 0.0_dp
      c_tan = 0.0_dp
      select case (kind)
      case (LINK_SPRING, LINK_BAR)
         f = par(L_STIFF)*du
         k_tan = par(L_STIFF)
         f_committed_new = f
      case (LINK_DASHPOT)
         f = par(L_DAMP)*dv
         c_tan = par(L_DAMP)
         f_committed_new = 0.0_dp
      case (LINK_BILINEAR)
         call bilinear_return_map(par(L_STIFF), par(L_YIELD), par(L_HARDENING), &
                                  state_f, state_u, du, f, k_tan, yielding)
         f_committed_new = f
      case (LINK_FLUID_DAMPER)
         call fluid_damper_force(par(L_DAMP), par(L_ALPHA), par(L_VREG), dv, f, c_tan)
         f_committed_new = 0.0_dp
      case default
         f = nan()
         k_tan = f
         c_tan = f
         f_committed_new = f
      end select
   end subroutine link_force

   elemental logical function link_is_known(kind)
      integer, intent(in) :: kind
      link_is_known = kind >= LINK_SPRING .and. kind <= LINK_BAR
   end function link_is_known

   pure function nan() result(x)
      real(dp) :: x
      x = ieee_value(1.0_dp, ieee_quiet_nan)
   end function nan

end module martello_links
