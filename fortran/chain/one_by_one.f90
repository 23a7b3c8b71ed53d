!> The fused chain step's other elements one by one (docs/run-layer.md "The fused chain
!> step"): the bilinear springs and the contacts that are not a pair's first (to ground, a
!> second one on a pair), evaluated after the sweeps at each iterate, and their tangents on
!> the factors' branches, per node.
submodule (martello_chain_step) one_by_one
   implicit none

contains

   !> The bilinear links and the other contacts at the iterate, one by one (after the sweep:
   !> fe holds the rest): forces into fe, branches, works.
   module procedure others
      integer :: n
      n = self%n
      associate (x => self%store)
         call at_state(x(self%ou:self%ou + n), x(self%ov:self%ov + n), x(self%oun:self%oun + n), &
                       x(self%ovn:self%ovn + n), x(self%ofe:self%ofe + n))
      end associate
   contains
      subroutine at_state(u, v, un, vn, fe)
         real(dp), intent(in) :: u(0:n), v(0:n), un(0:n), vn(0:n)
         real(dp), intent(inout) :: fe(0:n)
         integer :: idx, j, a, b
         real(dp) :: du, f, kt, pen, penn, fn
         logical :: yielding
         integer(int8) :: br
         associate (par => m%link_par)
            do idx = 1, size(self%blk%bl)
               ! the return map from the committed state
               j = self%blk%bl(idx); a = row_a(m%lnk, j); b = row_b(m%lnk, j)
               du = u(a) - u(b)
               call bilinear_return_map(par(L_STIFF, j), par(L_YIELD, j), par(L_HARDENING, j), &
                                        self%bfc(idx), self%bdu(idx), du, f, kt, yielding)
               br = B_ELASTIC
               if (yielding) br = merge(B_UPPER, B_LOWER, f > par(L_HARDENING, j)*par(L_STIFF, j)*du)
               self%bbr(idx) = br
               flipped = flipped .or. br /= self%bbrf(idx)
               self%wl = self%wl + 0.5_dp*(self%bfc(idx) + f)*(du - self%bdu(idx))
               self%bft(idx) = f; self%bdut(idx) = du
               fe(a) = fe(a) + f; fe(b) = fe(b) - f
            end do
            do idx = 1, size(self%blk%xg)
               j = self%blk%xg(idx); a = row_a(m%con, j); b = row_b(m%con, j)
               pen = u(a) - u(b) - m%con_gap(j)
               call contact_law(m, j, pen, v(a) - v(b), br, f)
               self%xbr(idx) = br
               flipped = flipped .or. br /= self%xbrf(idx)
               penn = un(a) - un(b) - m%con_gap(j)
               call contact_law(m, j, penn, vn(a) - vn(b), br, fn, self%xbrc(idx))
               self%wc = self%wc + 0.5_dp*(fn + f)*(pen - penn)
               fe(a) = fe(a) + f; fe(b) = fe(b) - f
            end do
            fe(0) = 0.0_dp
         end associate
      end subroutine at_state
   end procedure others

   !> Contact j's force f at δ = pen, δ̇ = rate and its branch br: on its whole law, or on
   !> the given branch on (the committed one).
   subroutine contact_law(m, j, pen, rate, br, f, on)
      type(model_t), intent(in) :: m
      integer, intent(in) :: j
      real(dp), intent(in) :: pen, rate
      integer(int8), intent(out) :: br
      real(dp), intent(out) :: f
      integer(int8), intent(in), optional :: on
      br = BRANCH_OFF; f = 0.0_dp
      if (present(on)) then
         if (on /= BRANCH_ON) return
      else if (.not. (pen > 0.0_dp)) then
         return
      end if
      br = BRANCH_ON
      f = m%con_par(P_STIFF, j)*pen
      if (m%con_law(j) == LAW_KELVIN) then
         f = f + m%con_par(P_DAMPING, j)*rate
         if (.not. present(on) .and. m%con_par(P_CLIP, j) > 0.5_dp .and. f <= 0.0_dp) then
            f = 0.0_dp; br = BRANCH_CLIPPED
         end if
      end if
   end subroutine contact_law

   !> The other elements' tangents on their current branches, per node: xjd, xjo of
   !> K_t + c_v C_t and C_t alone in xcd, xco (what the factors are made with).
   module procedure others_tangent
      integer :: idx, j
      real(dp) :: k, c
      self%xjd = 0.0_dp; self%xjo = 0.0_dp; self%xcd = 0.0_dp; self%xco = 0.0_dp
      do idx = 1, size(self%blk%bl)
         j = self%blk%bl(idx)
         k = m%link_par(L_STIFF, j)
         if (self%bbr(idx) /= B_ELASTIC) k = m%link_par(L_HARDENING, j)*k
         call stencil(row_a(m%lnk, j), row_b(m%lnk, j), k, 0.0_dp)
      end do
      do idx = 1, size(self%blk%xg)
         j = self%blk%xg(idx)
         if (self%xbr(idx) /= BRANCH_ON) cycle
         c = 0.0_dp
         if (m%con_law(j) == LAW_KELVIN) c = m%con_par(P_DAMPING, j)
         call stencil(row_a(m%con, j), row_b(m%con, j), m%con_par(P_STIFF, j), c)
      end do
      self%xjd(0) = 0.0_dp; self%xcd(0) = 0.0_dp
   contains
      !> J += k + c_v c, C_t += c on the two-node stencil of (i, l): |i − l| ≤ 1 or one end
      !> on ground (0).
      subroutine stencil(i, l, k, c)
         integer, intent(in) :: i, l
         real(dp), intent(in) :: k, c
         real(dp) :: val
         val = k + self%cv*c
         self%xjd(i) = self%xjd(i) + val; self%xjd(l) = self%xjd(l) + val
         self%xcd(i) = self%xcd(i) + c; self%xcd(l) = self%xcd(l) + c
         if (i > 0 .and. l > 0) then
            self%xjo(min(i, l)) = self%xjo(min(i, l)) - val
            self%xco(min(i, l)) = self%xco(min(i, l)) - c
         end if
      end subroutine stencil
   end procedure others_tangent
end submodule one_by_one
