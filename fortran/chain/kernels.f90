!> The fused chain step's sweeps (docs/run-layer.md "The fused chain step"), one kernel each
!> on explicit-shape arrays: no descriptors and no aliasing, so the compiler keeps every
!> scalar in a register and streams the arrays. J = c_m M + K_t + c_v C_t of a chain is
!> tridiagonal, factorised J = L D Lᵀ with reciprocal pivots rp(i) = 1/D_ii; L(i+1, i) is
!> computed again from the branch bytes where a sweep needs it (coupling). The parameter
!> arrays of the pair contacts are read at i·stride (stride 0: one value for the chain);
!> logical flags say which kinds of element the chain has (pl: links between neighbours;
!> pcs: pair contacts; kel: a Kelvin law among them; oth: other elements one by one, their
!> tangents per node in xjd, xjo, xcd, xco; fx: a fixed node).
module martello_chain_kernels
   use, intrinsic :: iso_fortran_env, only: int8
   use martello_kinds, only: dp
   use martello_contact_laws, only: BRANCH_OFF, BRANCH_ON, BRANCH_CLIPPED, AFFINE_LINEAR, &
      AFFINE_KELVIN_CLIPPED
   implicit none
   private
   public :: forward_kernel, refactor_kernel, back_kernel, coupling

contains

   !> The forward sweep of the first iterate (martello_chain_step linearised_sweep) on explicit-shape arrays (no descriptors, no aliasing: the
   !> compiler keeps everything in registers but the arrays).
   subroutine forward_kernel(n, h, gm, c1, c2, cv, acc, pl, kel, oth, pcs, fx, sk, sc, vn, an, &
                             sm, mass, fe, rp, cg, kp, cp, pk, pc, brf, xcd, xco, xjo, fixed)
      integer, intent(in), value :: n, sk, sc, sm
      real(dp), intent(in), value :: h, gm, c1, c2, cv, acc
      logical, intent(in), value :: pl, kel, oth, pcs, fx
      real(dp), intent(in) :: vn(0:n), an(0:n), mass(*), rp(n), cg(n), kp(0:*), cp(0:*), &
                              pk(0:*), pc(0:*), xcd(0:*), xco(0:*), xjo(0:*)
      integer(int8), intent(in) :: brf(0:n)
      logical, intent(in) :: fixed(n)
      real(dp), intent(inout) :: fe(0:n)     !< in: the committed internal force; out: y
      integer :: i
      real(dp) :: dvm, dv0, dvp, a0, ap, cdv, cd, co, com, ym, g1, lm
      ! a₀ = −c₁vₙ − c₂aₙ and Δv₀ = v₀ − vₙ = h((1 − γ)aₙ + γa₀) of each node
      g1 = 1.0_dp - gm
      dvm = 0.0_dp; com = 0.0_dp; ym = 0.0_dp; lm = 0.0_dp
      a0 = -c1*vn(1) - c2*an(1)
      dv0 = h*(g1*an(1) + gm*a0)
      do i = 1, n
         ap = 0.0_dp; dvp = 0.0_dp
         if (i < n) then
            ap = -c1*vn(i + 1) - c2*an(i + 1)
            dvp = h*(g1*an(i + 1) + gm*ap)
         end if
         ! C_t(i, i) and C_t(i, i+1) on the factors' branches
         cd = cg(i); co = 0.0_dp
         if (pl) then
            cd = cd + cp(i - 1) + cp(i); co = -cp(i)
         end if
         if (kel) then
            if (brf(i - 1) == BRANCH_ON) cd = cd + pc((i - 1)*sc)
            if (brf(i) == BRANCH_ON) then
               cd = cd + pc(i*sc); co = co - pc(i*sc)
            end if
         end if
         if (oth) then
            cd = cd + xcd(i); co = co + xco(i)
         end if
         cdv = cd*dv0 + com*dvm + co*dvp
         ym = mass(1 + (i - 1)*sm)*(acc - a0) - fe(i) - cdv - lm*ym
         fe(i) = ym
         dvm = dv0; dv0 = dvp; a0 = ap; com = co
         ! L(i+1, i) for the next node
         if (i < n) lm = coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, brf, xjo, &
                                  fixed)*rp(i)
      end do
      fe(0) = 0.0_dp
   end subroutine forward_kernel

   !> The forward sweep after a branch change (martello_chain_step refactor_sweep): J on the
   !> current branches factorised, the residual forward-substituted; ok = .false. on a pivot
   !> that is not > 0.
   subroutine refactor_kernel(n, cm, cv, acc, pl, pcs, oth, sk, sc, a, sm, mass, fixed, fe, kg, &
                              cg, kp, cp, pk, pc, br, xjd, xjo, rp, ok)
      integer, intent(in) :: n, sk, sc, sm
      real(dp), intent(in) :: cm, cv, acc
      logical, intent(in) :: pl, pcs, oth, fixed(n)
      real(dp), intent(in) :: a(0:n), mass(*), kg(n), cg(n), kp(0:*), cp(0:*), pk(0:*), pc(0:*), &
                              xjd(0:*), xjo(0:*)
      real(dp), intent(inout) :: fe(0:n)     !< in: the internal force at the iterate; out: y
      integer(int8), intent(in) :: br(0:n)
      real(dp), intent(out) :: rp(n)
      logical, intent(out) :: ok
      integer :: i
      real(dp) :: p, jd, jo, jom, tp, tpm, ym, gm
      ok = .true.
      tpm = 0.0_dp; gm = 0.0_dp; ym = 0.0_dp; jom = 0.0_dp
      do i = 1, n
         ! tp: the tangent of pair (i, i+1), K_t + c_v C_t
         tp = 0.0_dp
         if (i < n) then
            if (pl) tp = kp(i) + cv*cp(i)
            if (pcs) then
               if (br(i) == BRANCH_ON) tp = tp + (pk(i*sk) + cv*pc(i*sc))
            end if
         end if
         jd = kg(i) + cv*cg(i) + tpm + tp
         if (oth) jd = jd + xjd(i)
         ! J(i, i+1) as the sweeps compute it again (coupling)
         jo = 0.0_dp
         if (i < n) jo = coupling(i, cv, pl, pcs, oth, .true., sk, sc, kp, cp, pk, pc, br, xjo, fixed)
         if (fixed(i)) then
            p = 1.0_dp
         else
            p = cm*mass(1 + (i - 1)*sm) + jd - jom*gm
         end if
         if (.not. (p > 0.0_dp)) ok = .false.
         rp(i) = 1.0_dp/p
         if (fixed(i)) then
            ym = 0.0_dp
         else
            ym = mass(1 + (i - 1)*sm)*(acc - a(i)) - fe(i) - gm*ym
         end if
         gm = jo*rp(i)
         fe(i) = ym
         tpm = tp; jom = jo
      end do
      fe(0) = 0.0_dp
   end subroutine refactor_kernel

   !> J(i, i+1), i < n, of the factors made on the branches brf: −(K_t + c_v C_t) of the pair
   !> (i, i+1) (its summed links, its contact where on), plus the other elements' (xjo), 0 at
   !> a fixed row or column (fx: some node is fixed). L(i+1, i) = J(i, i+1)·rp(i): the sweeps
   !> compute it again from the branch bytes rather than read it from an array (8 B per node
   !> less to keep, and to stream at every step), to the same bits as the factorisation.
   pure real(dp) function coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, brf, xjo, &
                                   fixed) result(jo)
      integer, intent(in) :: i, sk, sc
      real(dp), intent(in) :: cv, kp(0:*), cp(0:*), pk(0:*), pc(0:*), xjo(0:*)
      logical, intent(in) :: pl, pcs, oth, fx, fixed(*)
      integer(int8), intent(in) :: brf(0:*)
      real(dp) :: tp
      tp = 0.0_dp
      if (pl) tp = kp(i) + cv*cp(i)
      if (pcs) then
         if (brf(i) == BRANCH_ON) tp = tp + (pk(i*sk) + cv*pc(i*sc))
      end if
      jo = -tp
      if (oth) jo = jo + xjo(i)
      if (fx) then
         if (fixed(i) .or. fixed(i + 1)) jo = 0.0_dp
      end if
   end function coupling

   !> The backward sweep and the elements at the new iterate (martello_chain_step evaluate) (no descriptors, no aliasing). The parameter
   !> arrays of the pair contacts are read at i·stride (stride 0: one value for the chain).
   subroutine back_kernel(n, from_start, pl, pcs, kel, oth, fx, ss, sg, sk, sc, sl, cm, cv, c1, &
                          c2, h, gm, rp, u, v, a, un, vn, an, sm, mass, fe, kg, cg, kp, cp, psgn, &
                          pgap, pk, pc, plaw, pbr, pbrc, pbrf, xjo, fixed, mdu, wd, wl, wc, flip)
      integer, intent(in), value :: n, ss, sg, sk, sc, sl, sm
      logical, intent(in), value :: from_start, pl, pcs, kel, oth, fx
      real(dp), intent(in), value :: cm, cv, c1, c2, h, gm
      real(dp), intent(in) :: rp(n), un(0:n), vn(0:n), an(0:n), mass(*), kg(n), &
                              cg(n), kp(0:*), cp(0:*), psgn(0:*), pgap(0:*), pk(0:*), pc(0:*), &
                              xjo(0:*)
      logical, intent(in) :: fixed(n)
      integer(int8), intent(in) :: plaw(0:*), pbrc(0:n), pbrf(0:n)
      real(dp), intent(inout) :: u(0:n), v(0:n), a(0:n)
      real(dp), intent(inout) :: fe(0:n)     !< in: y; out: the internal force
      integer(int8), intent(inout) :: pbr(0:n)
      real(dp), intent(out) :: mdu, wd, wl, wc
      logical, intent(out) :: flip
      integer :: i
      integer(int8) :: br, law
      real(dp) :: x, ui, vi, ai, uni, vni, u1, v1, un1, vn1, fi, f1, du, dun, fp, s, pen, penn, &
                  f, fn, gp, g1, k, c, hd, lx
      g1 = 1.0_dp - gm
      mdu = 0.0_dp; wd = 0.0_dp; wl = 0.0_dp; wc = 0.0_dp; flip = .false.
      x = 0.0_dp; u1 = 0.0_dp; v1 = 0.0_dp; un1 = 0.0_dp; vn1 = 0.0_dp; f1 = 0.0_dp
      do i = n, 1, -1
         ! Δu(i) = D⁻¹y(i) − L(i+1, i)·Δu(i+1)
         lx = 0.0_dp
         if (i < n) lx = coupling(i, cv, pl, pcs, oth, fx, sk, sc, kp, cp, pk, pc, pbrf, xjo, &
                                  fixed)*rp(i)*x
         x = rp(i)*fe(i) - lx
         uni = un(i); vni = vn(i)
         if (from_start) then
            ! the Newmark a₀, v₀ of u = uₙ, as the general path's kinematics associate them
            ai = -c1*vni - c2*an(i)
            vi = vni + h*(g1*an(i) + gm*ai) + cv*x
            ai = ai + cm*x
            ui = uni + x
         else
            ui = u(i) + x; vi = v(i) + cv*x; ai = a(i) + cm*x
         end if
         u(i) = ui; v(i) = vi; a(i) = ai
         mdu = mdu + mass(1 + (i - 1)*sm)*x
         ! the links of node i to ground
         k = kg(i); c = cg(i); hd = 0.5_dp*(ui - uni)
         fi = k*ui + c*vi
         wl = wl + k*(uni + ui)*hd
         wd = wd + c*(vni + vi)*hd
         if (i < n) then
            ! the pair (i, i+1): node i+1 is known
            du = ui - u1; dun = uni - un1
            if (pl) then
               fp = kp(i)*du + cp(i)*(vi - v1)
               wl = wl + 0.5_dp*kp(i)*(dun + du)*(du - dun)
               wd = wd + 0.5_dp*cp(i)*((vni - vn1) + (vi - v1))*(du - dun)
               fi = fi + fp; f1 = f1 - fp
            end if
            if (pcs) then
               ! linear or Kelvin (Anagnostopoulos 1988), as martello_contact_laws
               s = psgn(i*ss); gp = pgap(i*sg)
               pen = s*du - gp; penn = s*dun - gp
               br = BRANCH_OFF; f = 0.0_dp
               if (pen > 0.0_dp) then
                  br = BRANCH_ON; f = pk(i*sk)*pen
                  if (kel) then
                     law = plaw(i*sl)
                     if (law /= AFFINE_LINEAR) then
                        f = f + pc(i*sc)*(s*(vi - v1))
                        if (law == AFFINE_KELVIN_CLIPPED .and. f <= 0.0_dp) then
                           f = 0.0_dp; br = BRANCH_CLIPPED
                        end if
                     end if
                  end if
               end if
               pbr(i) = br
               if (br /= pbrf(i)) flip = .true.
               fn = 0.0_dp
               if (pbrc(i) == BRANCH_ON) then
                  fn = pk(i*sk)*penn
                  if (kel) fn = fn + pc(i*sc)*(s*(vni - vn1))
               end if
               wc = wc + 0.5_dp*(fn + f)*(pen - penn)
               fi = fi + s*f; f1 = f1 - s*f
            end if
            fe(i + 1) = f1
         end if
         f1 = fi
         u1 = ui; v1 = vi; un1 = uni; vn1 = vni
      end do
      fe(1) = f1
      fe(0) = 0.0_dp
   end subroutine back_kernel
end module martello_chain_kernels
