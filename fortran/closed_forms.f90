!> Closed-form solutions of catalogue problems for C and Fortran callers
!> (the formulas of docs/problems.md P1, P2 and P5; the C door is martello_api_closed_forms),
!> so that a code linking the library can check itself without the Python oracles. Each
!> closed form takes its parameters in a fixed order and writes a fixed number of values
!> (CLOSED_FORMS below, the table in docs/c-api.md "Closed forms").
module martello_closed_forms
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK, MARTELLO_ERR_ARGUMENT
   implicit none
   private
   public :: closed_form

   real(dp), parameter :: PI = acos(-1.0_dp)

contains

   !> The closed form called name at par: out(1:n_out) and n_out, stat MARTELLO_OK; or stat
   !> MARTELLO_ERR_ARGUMENT for an unknown name, a wrong parameter count or parameters out of
   !> the form's domain (masses, stiffnesses not > 0, e not in [0, 1], a plane P2 never reaches).
   subroutine closed_form(name, par, out, n_out, stat)
      character(len=*), intent(in) :: name
      real(dp), intent(in) :: par(:)
      real(dp), intent(out) :: out(4)
      integer, intent(out) :: n_out, stat
      real(dp) :: m, k, h, g, eps, f_r, m1, m2, ms, dv, e, us, w, c, v0, dm
      stat = MARTELLO_ERR_ARGUMENT; n_out = 0; out = 0.0_dp
      select case (name)
      case ('p1_static_lagrange', 'p1_static_penalty')
         ! P1: spring k holds m under gravity g above a plane at h: (u, lambda, force, pen)
         if (size(par) /= merge(4, 5, name == 'p1_static_lagrange')) return
         m = par(1); k = par(2); h = par(3); g = par(4)
         if (.not. (m > 0.0_dp .and. k > 0.0_dp)) return
         f_r = k*h - m*g                         ! negative iff the plane is reached
         n_out = 4
         if (f_r >= 0.0_dp) then
            out = [m*g/k, 0.0_dp, 0.0_dp, 0.0_dp]
         else if (name == 'p1_static_lagrange') then
            out = [h, f_r, -f_r, 0.0_dp]
         else
            eps = par(5)
            if (.not. eps > 0.0_dp) return
            out(4) = (m*g - k*h)/(k + eps)        ! penetration, without cancellation
            out(2) = eps*f_r/(k + eps)
            out(1) = h + out(4); out(3) = -out(2)
         end if
      case ('p2_first_impact')
         ! P2: released at rest, u = u_s (1 − cos ωt), u_s = m g/k, reaches the plane at h:
         ! (t_impact, v_impact)
         if (size(par) /= 4) return
         m = par(1); k = par(2); h = par(3); g = par(4)
         if (.not. (m > 0.0_dp .and. k > 0.0_dp .and. g > 0.0_dp .and. h > 0.0_dp)) return
         us = m*g/k; w = sqrt(k/m)
         if (.not. h < 2.0_dp*us) return
         c = 1.0_dp - h/us
         out(1) = acos(c)/w; out(2) = us*w*sqrt(1.0_dp - c*c); n_out = 2
      case ('p5_newton')
         ! P5: Newton's impact of m1 at v1 on m2 at v2 with e: (v1', v2', energy lost)
         if (size(par) /= 5) return
         m1 = par(1); m2 = par(2); e = par(5)
         if (.not. (m1 > 0.0_dp .and. m2 > 0.0_dp .and. e >= 0.0_dp .and. e <= 1.0_dp)) return
         dv = par(3) - par(4); ms = m1*m2/(m1 + m2)
         out(1) = par(3) - (1.0_dp + e)*m2*dv/(m1 + m2)
         out(2) = par(4) + (1.0_dp + e)*m1*dv/(m1 + m2)
         out(3) = 0.5_dp*(1.0_dp - e*e)*ms*dv*dv; n_out = 3
      case ('p5_linear', 'p5_hertz')
         ! P5: approach at v0, m* = m1 m2/(m1 + m2), F = k δ (linear) or k δ^{3/2} (Hertz):
         ! (max penetration, contact time, max force)
         if (size(par) /= 4) return
         m1 = par(1); m2 = par(2); k = par(3); v0 = par(4)
         if (.not. (m1 > 0.0_dp .and. m2 > 0.0_dp .and. k > 0.0_dp .and. v0 > 0.0_dp)) return
         ms = m1*m2/(m1 + m2)
         if (name == 'p5_linear') then
            dm = v0*sqrt(ms/k)
            out(1:3) = [dm, PI*sqrt(ms/k), k*dm]
         else
            ! δ_max = (5 m* v0²/(4 k))^{2/5}; t_c = 2 (2/5) B(2/5, 1/2) δ_max/v0
            dm = (5.0_dp*ms*v0*v0/(4.0_dp*k))**0.4_dp
            out(1:3) = [dm, 0.8_dp*gamma(0.4_dp)*gamma(0.5_dp)/gamma(0.9_dp)*dm/v0, k*dm**1.5_dp]
         end if
         n_out = 3
      case default
         return
      end select
      stat = MARTELLO_OK
   end subroutine closed_form
end module martello_closed_forms
