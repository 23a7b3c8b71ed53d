!> Sub-models for local stepping (docs/run-layer.md, "Sub-models for local stepping"): the model
!> of a cluster of free nodes — its nodes, the fixed nodes its elements touch, every element whose
!> free nodes all lie in it, their loads — built from the parent's cached node incidence in
!> O(cluster + the items it touches), and the transfer of the elements' state between the
!> parent's evaluator and a sub-model's. A sub-model's forces are the parent's rows for its
!> nodes, bit for bit, when every element left out is an open contact: its nodes keep the
!> parent's order and its elements the parent's, so every sum is taken in the same order.
module martello_submodel
   use martello_kinds, only: dp
   use martello_status, only: MARTELLO_OK, MARTELLO_ERR_ARGUMENT, out_of_memory, INT_BYTES, &
      FIX_SMALLER_SCENE
   use martello_model, only: model_t, model_init, model_has_influence
   use martello_node_incidence, only: node_incidence_t, INCIDENCE_KEYS
   use martello_element_rows, only: rows_append, rows_terms
   use martello_evaluator, only: evaluator_t
   use martello_assembly, only: mech_state_t
   implicit none
   private
   public :: submodel_map_t, submodel_build, submodel_transfer, model_clusters

   !> The parent's number (1-based) of each node, link, contact and stiffness block of a
   !> sub-model.
   type :: submodel_map_t
      integer, allocatable :: node(:), link(:), contact(:), block(:)
   end type submodel_map_t

contains

   !> The node → element and node → force incidence of m (node_incidence_t), built unless it
   !> is already there for m's sizes. stat: MARTELLO_ERR_MEMORY (message in m%errmsg).
   subroutine incidence_update(m, stat)
      type(model_t), intent(inout) :: m
      integer, intent(out) :: stat
      integer :: key(INCIDENCE_KEYS), nl, nc, ncp, j, k, ne
      integer, allocatable :: cnt(:)
      stat = MARTELLO_OK
      nl = m%nlink; nc = m%ncontact; ncp = m%ncoupling
      key = [m%n, nl, nc, ncp, m%nblock, m%nforce, rows_terms(m%lnk), rows_terms(m%con)]
      if (all(m%incidence%built_for == key)) return
      ne = nl + nc + ncp + m%nblock
      associate (inc => m%incidence)
         inc%built_for = -1
         if (allocated(inc%efirst)) deallocate (inc%efirst, inc%elem, inc%ffirst, inc%force, &
                                                inc%elem_mark, inc%node_mark)
         allocate (inc%efirst(m%n + 1), inc%ffirst(m%n + 1), inc%elem_mark(ne), &
                   inc%node_mark(m%n), cnt(m%n + 1), stat=stat)
         if (stat == 0) then
            ! counts per node, then the offsets, then the items in ascending order
            cnt = 0
            call each_element(.false.)
            inc%efirst(1) = 1
            do j = 1, m%n
               inc%efirst(j + 1) = inc%efirst(j) + cnt(j)
            end do
            allocate (inc%elem(inc%efirst(m%n + 1) - 1), stat=stat)
         end if
         if (stat == 0) then
            cnt(1:m%n) = inc%efirst(1:m%n)
            call each_element(.true.)
            cnt = 0
            do j = 1, m%nforce
               cnt(m%force_node(j)) = cnt(m%force_node(j)) + 1
            end do
            inc%ffirst(1) = 1
            do j = 1, m%n
               inc%ffirst(j + 1) = inc%ffirst(j) + cnt(j)
            end do
            allocate (inc%force(m%nforce), stat=stat)
         end if
         if (stat /= 0) then
            call out_of_memory('the node incidence of the model (for its sub-models)', &
                               INT_BYTES*(4.0_dp*m%n + 2.0_dp*ne + m%nforce &
                                          + rows_terms(m%lnk) + rows_terms(m%con)), &
                               FIX_SMALLER_SCENE, stat, m%errmsg)
            if (allocated(inc%efirst)) deallocate (inc%efirst)
            return
         end if
         cnt(1:m%n) = inc%ffirst(1:m%n)
         do j = 1, m%nforce
            k = m%force_node(j)
            inc%force(cnt(k)) = j; cnt(k) = cnt(k) + 1
         end do
         inc%elem_mark = 0; inc%node_mark = 0
         inc%built_for = key
      end associate
   contains
      !> every node i of every element e (numbered as node_incidence_t's): counted in cnt(i),
      !> or (place) put at elem(cnt(i)), cnt(i) moved on
      subroutine each_element(place)
         logical, intent(in) :: place
         integer :: e, q
         do e = 1, nl
            do q = m%lnk%first(e), m%lnk%first(e + 1) - 1
               call visit(e, m%lnk%node(q), place)
            end do
         end do
         do e = 1, nc
            do q = m%con%first(e), m%con%first(e + 1) - 1
               call visit(nl + e, m%con%node(q), place)
            end do
         end do
         do e = 1, ncp
            call visit(nl + nc + e, m%mc_a(e), place); call visit(nl + nc + e, m%mc_b(e), place)
         end do
         do e = 1, m%nblock
            do q = 1, size(m%block(e)%node)
               call visit(nl + nc + ncp + e, m%block(e)%node(q), place)
            end do
         end do
      end subroutine each_element
      subroutine visit(e, i, place)
         integer, intent(in) :: e, i
         logical, intent(in) :: place
         if (place) m%incidence%elem(cnt(i)) = e
         cnt(i) = cnt(i) + 1
      end subroutine visit
   end subroutine incidence_update

   !> The sub-model sub of p on the free nodes nodes(:) (1-based, any order): sub's nodes are
   !> those and the fixed nodes their elements touch, in p's order (so its half-bandwidth is at
   !> most p's); its contacts every one of p's whose free nodes all lie in nodes(:), in p's
   !> order, with p's parameters and effective masses (one with a free node outside is left
   !> out: an open contact between clusters); its links, mass couplings and stiffness blocks
   !> likewise, but one with a free node outside is refused (it always joins its nodes' cluster:
   !> the cluster would be cut); the nodal forces of its nodes; p's gravity, influence and
   !> ground motion.
   !> map: p's number of each of sub's items. stat: MARTELLO_ERR_ARGUMENT (p%errmsg says
   !> which argument and the fix), MARTELLO_ERR_MEMORY. Cost O(size(nodes) + the items they
   !> touch) once p's incidence is built (O(p) once).
   subroutine submodel_build(p, nodes, sub, map, stat)
      type(model_t), intent(inout) :: p
      integer, intent(in) :: nodes(:)
      type(model_t), intent(inout) :: sub
      type(submodel_map_t), intent(out) :: map
      integer, intent(out) :: stat
      integer, allocatable :: elems(:), fixed_extra(:), forces(:)
      logical, allocatable :: keep(:)
      integer :: nel, nfx, k, q, e, i, nl, nc, ncp, nb, nf, bound
      character(len=200) :: why
      stat = MARTELLO_ERR_ARGUMENT
      if (p%nchain > 0) then
         p%errmsg = 'model_subset: the model holds chains per node (model_add_chain); take the'// &
                    ' sub-model of its expanded copy (martello_model_expand_chains first)'
         return
      end if
      if (size(nodes) < 1) then
         p%errmsg = 'model_subset: n must be >= 1 (a cluster has at least one free node)'; return
      end if
      call incidence_update(p, stat)
      if (stat /= MARTELLO_OK) return
      stat = MARTELLO_ERR_ARGUMENT
      nel = 0; nfx = 0; why = ''
      associate (inc => p%incidence, mark => p%incidence%node_mark, emark => p%incidence%elem_mark)
         ! the cluster's nodes marked 1 (a fixed node joining it: 2; its sub number at the end)
         do k = 1, size(nodes)
            i = nodes(k)
            if (i < 1 .or. i > p%n) then
               write (why, '(a,i0,a,i0,a,i0,a)') 'model_subset: nodes[', k - 1, '] = ', i - 1, &
                  ' is not a node of the model (0 ... ', p%n - 1, ')'
            else if (p%fixed(i)) then
               write (why, '(a,i0,a,i0,a)') 'model_subset: nodes[', k - 1, '] = ', i - 1, &
                  ' is a fixed node: give the free nodes of the cluster (the fixed nodes its'// &
                  ' elements touch join the sub-model on their own)'
            else if (mark(i) /= 0) then
               write (why, '(a,i0,a)') 'model_subset: node ', i - 1, ' is given twice in nodes'
            end if
            if (len_trim(why) > 0) then
               call unmark(k - 1)
               p%errmsg = why; return
            end if
            mark(i) = 1
         end do
         bound = 0
         do k = 1, size(nodes)
            bound = bound + inc%efirst(nodes(k) + 1) - inc%efirst(nodes(k))
         end do
         allocate (elems(bound), keep(bound), stat=stat)
         if (stat /= 0) then
            call unmark(size(nodes))
            call out_of_memory('a sub-model''s element list', INT_BYTES*2.0_dp*bound, &
                               FIX_SMALLER_SCENE, stat, p%errmsg)
            return
         end if
         ! the elements touching the cluster, each once
         do k = 1, size(nodes)
            do q = inc%efirst(nodes(k)), inc%efirst(nodes(k) + 1) - 1
               e = inc%elem(q)
               if (emark(e) /= 0) cycle
               emark(e) = 1
               nel = nel + 1; elems(nel) = e
            end do
         end do
         ! kept: every free node inside; the fixed nodes of the kept ones join
         allocate (fixed_extra(elem_terms()), stat=stat)
         if (stat /= 0) then
            call clear_and_fail()
            return
         end if
         do k = 1, nel
            call classify(elems(k), keep(k))
            if (len_trim(why) > 0) exit
         end do
         if (len_trim(why) > 0) then
            call clear_elements(); call unmark(size(nodes)); call unmark_extra()
            stat = MARTELLO_ERR_ARGUMENT; p%errmsg = why; return
         end if
         ! sub's nodes in p's order, numbered in mark
         allocate (map%node(size(nodes) + nfx), stat=stat)
         if (stat /= 0) then
            call clear_and_fail()
            return
         end if
         map%node(1:size(nodes)) = nodes
         map%node(size(nodes) + 1:) = fixed_extra(1:nfx)
         call sort_ints(map%node)
         do k = 1, size(map%node)
            mark(map%node(k)) = k
         end do
         call clear_elements()
         elems = pack(elems(1:nel), keep(1:nel))
         call sort_ints(elems)
         nl = count(elems <= p%nlink)
         nc = count(elems > p%nlink .and. elems <= p%nlink + p%ncontact)
         ncp = count(elems > p%nlink + p%ncontact .and. elems <= p%nlink + p%ncontact + p%ncoupling)
         nb = size(elems) - nl - nc - ncp
         ! the nodal forces of sub's nodes, in p's order
         bound = 0
         do k = 1, size(map%node)
            bound = bound + inc%ffirst(map%node(k) + 1) - inc%ffirst(map%node(k))
         end do
         allocate (forces(bound), stat=stat)
         if (stat == 0) then
            nf = 0
            do k = 1, size(map%node)
               do q = inc%ffirst(map%node(k)), inc%ffirst(map%node(k) + 1) - 1
                  nf = nf + 1; forces(nf) = inc%force(q)
               end do
            end do
            call sort_ints(forces)
            map%link = elems(1:nl)
            map%contact = elems(nl + 1:nl + nc) - p%nlink
            map%block = elems(nl + nc + ncp + 1:) - (p%nlink + p%ncontact + p%ncoupling)
            call model_init(sub, size(map%node), nl, nc, nf, ncp, stat)
            if (stat /= MARTELLO_OK) p%errmsg = sub%errmsg
         end if
         if (stat == MARTELLO_OK) &
            call fill(elems(nl + nc + 1:nl + nc + ncp) - (p%nlink + p%ncontact))
         do k = 1, size(map%node)
            mark(map%node(k)) = 0
         end do
      end associate
   contains
      !> the terms of the gathered elements (a bound on the fixed nodes they add)
      integer function elem_terms() result(t)
         integer :: k
         integer, allocatable :: nd(:)
         t = 0
         do k = 1, nel
            call element_nodes(elems(k), nd)
            t = t + size(nd)
         end do
      end function elem_terms

      !> p's nodes of element e (numbered as node_incidence_t's)
      subroutine element_nodes(e, nd)
         integer, intent(in) :: e
         integer, allocatable, intent(out) :: nd(:)
         integer :: j, lo, hi
         if (e <= p%nlink) then
            lo = p%lnk%first(e); hi = p%lnk%first(e + 1) - 1
            allocate (nd(hi - lo + 1)); nd(:) = p%lnk%node(lo:hi)
         else if (e <= p%nlink + p%ncontact) then
            j = e - p%nlink
            lo = p%con%first(j); hi = p%con%first(j + 1) - 1
            allocate (nd(hi - lo + 1)); nd(:) = p%con%node(lo:hi)
         else if (e <= p%nlink + p%ncontact + p%ncoupling) then
            j = e - p%nlink - p%ncontact
            allocate (nd(2)); nd(:) = [p%mc_a(j), p%mc_b(j)]
         else
            j = e - p%nlink - p%ncontact - p%ncoupling
            allocate (nd(size(p%block(j)%node))); nd(:) = p%block(j)%node
         end if
      end subroutine element_nodes

      !> keep e if every free node of it is the cluster's (its fixed nodes then join); a
      !> contact with a free node outside is left out (an open contact between clusters, the
      !> caller's); a link, a coupling or a block with one: why says so (it always joins)
      subroutine classify(e, kept)
         integer, intent(in) :: e
         logical, intent(out) :: kept
         integer, allocatable :: nd(:)
         integer :: q, outside
         call element_nodes(e, nd)
         outside = 0
         do q = 1, size(nd)
            if (p%incidence%node_mark(nd(q)) == 0 .and. .not. p%fixed(nd(q))) outside = nd(q)
         end do
         kept = outside == 0
         if (.not. kept) then
            if (e > p%nlink + p%ncontact + p%ncoupling) then
               write (why, '(a,i0,a,i0,a)') 'model_subset: stiffness block ', &
                  e - p%nlink - p%ncontact - p%ncoupling - 1, ' has node ', outside - 1, &
                  ' outside the cluster: a block cannot be cut (give all its free nodes)'
            else if (e > p%nlink + p%ncontact) then
               q = e - p%nlink - p%ncontact
               write (why, '(a,i0,a,i0,a,i0,a)') 'model_subset: the mass coupling ', q - 1, &
                  ' between nodes ', p%mc_a(q) - 1, ' and ', p%mc_b(q) - 1, &
                  ' crosses the cut: a consistent mass cannot be cut (give both nodes)'
            else if (e <= p%nlink) then
               write (why, '(a,i0,a,i0,a)') 'model_subset: link ', e - 1, ' has node ', &
                  outside - 1, ' outside the cluster: a link always joins its nodes'' cluster'// &
                  ' (give all its free nodes)'
            end if
            return
         end if
         do q = 1, size(nd)
            if (p%incidence%node_mark(nd(q)) /= 0) cycle
            p%incidence%node_mark(nd(q)) = 2
            nfx = nfx + 1; fixed_extra(nfx) = nd(q)
         end do
      end subroutine classify

      subroutine clear_elements()
         integer :: k
         do k = 1, nel
            p%incidence%elem_mark(elems(k)) = 0
         end do
      end subroutine clear_elements

      subroutine unmark(upto)
         integer, intent(in) :: upto
         integer :: k
         do k = 1, upto
            p%incidence%node_mark(nodes(k)) = 0
         end do
      end subroutine unmark

      subroutine unmark_extra()
         integer :: k
         do k = 1, nfx
            p%incidence%node_mark(fixed_extra(k)) = 0
         end do
      end subroutine unmark_extra

      subroutine clear_and_fail()
         call clear_elements(); call unmark(size(nodes))
         if (allocated(fixed_extra)) call unmark_extra()
         call out_of_memory('a sub-model''s node list', INT_BYTES*2.0_dp*(size(nodes) + nel), &
                            FIX_SMALLER_SCENE, stat, p%errmsg)
      end subroutine clear_and_fail

      !> sub's arrays from p's through map, the nodes renumbered by mark
      subroutine fill(couplings)
         integer, intent(in) :: couplings(:)
         integer :: k, j, lo, hi, st
         st = 0
         associate (mark => p%incidence%node_mark, nd => map%node)
            sub%mass = p%mass(nd); sub%fixed = p%fixed(nd)
            if (size(p%u0) > 0) sub%u0 = p%u0(nd)
            if (size(p%v0) > 0) sub%v0 = p%v0(nd)
            if (model_has_influence(p)) sub%influence = p%influence(nd)
            do k = 1, nl
               j = map%link(k); lo = p%lnk%first(j); hi = p%lnk%first(j + 1) - 1
               call rows_append(sub%lnk, mark(p%lnk%node(lo:hi)), p%lnk%coef(lo:hi), st)
               if (st /= 0) exit
            end do
            do k = 1, nc
               if (st /= 0) exit
               j = map%contact(k); lo = p%con%first(j); hi = p%con%first(j + 1) - 1
               call rows_append(sub%con, mark(p%con%node(lo:hi)), p%con%coef(lo:hi), st)
            end do
            if (st /= 0) then
               call out_of_memory('a sub-model''s rows', 0.0_dp, FIX_SMALLER_SCENE, stat, p%errmsg)
               return
            end if
            sub%nlink = nl; sub%ncontact = nc
            sub%link_kind(1:nl) = p%link_kind(map%link)
            sub%link_par(:, 1:nl) = p%link_par(:, map%link)
            sub%con_scheme(1:nc) = p%con_scheme(map%contact)
            sub%con_law(1:nc) = p%con_law(map%contact)
            sub%con_gap(1:nc) = p%con_gap(map%contact)
            sub%con_par(:, 1:nc) = p%con_par(:, map%contact)
            sub%con_mstar(1:nc) = p%con_mstar(map%contact)
            sub%ncoupling = ncp
            sub%mc_a(1:ncp) = mark(p%mc_a(couplings)); sub%mc_b(1:ncp) = mark(p%mc_b(couplings))
            sub%mc_value(1:ncp) = p%mc_value(couplings)
            allocate (sub%block(nb))
            do k = 1, nb
               j = map%block(k)
               sub%block(k)%node = mark(p%block(j)%node)
               sub%block(k)%k = p%block(j)%k; sub%block(k)%c = p%block(j)%c
               sub%block(k)%damped = p%block(j)%damped
            end do
            sub%nblock = nb
            sub%nforce = nf
            do k = 1, nf
               sub%force_node(k) = mark(p%force_node(forces(k)))
               sub%force_fn(k) = p%force_fn(forces(k))
            end do
            sub%gravity = p%gravity
            sub%ground_accel = p%ground_accel
         end associate
      end subroutine fill
   end subroutine submodel_build

   !> The state of the elements of map (committed and trial: link histories, forces and
   !> branches; contact penetrations, rates, forces, onset speeds, on/off and branches; the
   !> stiffness blocks' states) and of sub's nodes (the last state loaded and its forces), from
   !> the parent's evaluator pe into the sub-model's se (to_sub) or back; to_sub also gives se
   !> pe's branch mode (evaluator_use_branches). se must be an evaluator of the sub-model map
   !> came with, pe of its parent: stat MARTELLO_ERR_ARGUMENT otherwise (message in the
   !> parent model's errmsg).
   subroutine submodel_transfer(pe, se, map, to_sub, stat)
      type(evaluator_t), intent(inout) :: pe, se
      type(submodel_map_t), intent(in) :: map
      logical, intent(in) :: to_sub
      integer, intent(out) :: stat
      integer :: k, j
      stat = MARTELLO_ERR_ARGUMENT
      if (size(map%node) /= se%m%n .or. size(map%link) /= se%m%nlink .or. &
          size(map%contact) /= se%m%ncontact .or. size(map%block) /= se%m%nblock) then
         pe%m%errmsg = 'eval_state_transfer: the map is not that of the sub evaluator''s model'// &
                       ' (give the map martello_model_subset filled with that sub-model)'
         return
      end if
      if (any(map%node < 1 .or. map%node > pe%m%n) .or. &
          any(map%link < 1 .or. map%link > pe%m%nlink) .or. any(map%contact < 1 .or. map%contact > pe%m%ncontact) .or. &
          any(map%block < 1 .or. map%block > pe%m%nblock)) then
         pe%m%errmsg = 'eval_state_transfer: the map points past the parent evaluator''s model'// &
                       ' (give the parent the sub-model was taken of)'
         return
      end if
      stat = MARTELLO_OK
      associate (s => se%ms, p => pe%ms, l => map%link, c => map%contact)
         call move_r(s%link_fc, p%link_fc, l); call move_r(s%link_u, p%link_u, l)
         call move_r(s%link_fc_trial, p%link_fc_trial, l)
         call move_r(s%link_f, p%link_f, l); call move_r(s%link_f_trial, p%link_f_trial, l)
         call move_i(s%link_branch, p%link_branch, l)
         call move_r(s%con_f, p%con_f, c); call move_r(s%con_f_trial, p%con_f_trial, c)
         call move_r(s%con_pen, p%con_pen, c); call move_r(s%con_pen_trial, p%con_pen_trial, c)
         call move_r(s%con_rate, p%con_rate, c); call move_r(s%con_rate_trial, p%con_rate_trial, c)
         call move_r(s%con_vin, p%con_vin, c); call move_r(s%con_vin_trial, p%con_vin_trial, c)
         call move_l(s%con_on, p%con_on, c); call move_l(s%forced_off, p%forced_off, c)
         call move_i(s%con_branch, p%con_branch, c)
         call move_r(s%blk_e, p%blk_e, map%block)
         do k = 1, size(map%block)
            j = map%block(k)
            if (to_sub) then
               s%blk(k) = p%blk(j)
            else
               p%blk(j) = s%blk(k)
            end if
         end do
      end associate
      call move_r(se%u(1:), pe%u(1:), map%node); call move_r(se%v(1:), pe%v(1:), map%node)
      call move_r(se%f(1:), pe%f(1:), map%node); call move_r(se%fext(1:), pe%fext(1:), map%node)
      if (to_sub) then
         se%branches = pe%branches; se%across = pe%across
      end if
   contains
      subroutine move_r(xs, xp, idx)
         real(dp), intent(inout) :: xs(:), xp(:)
         integer, intent(in) :: idx(:)
         if (to_sub) then
            xs = xp(idx)
         else
            xp(idx) = xs
         end if
      end subroutine move_r
      subroutine move_i(xs, xp, idx)
         integer, intent(inout) :: xs(:), xp(:)
         integer, intent(in) :: idx(:)
         if (to_sub) then
            xs = xp(idx)
         else
            xp(idx) = xs
         end if
      end subroutine move_i
      subroutine move_l(xs, xp, idx)
         logical, intent(inout) :: xs(:), xp(:)
         integer, intent(in) :: idx(:)
         if (to_sub) then
            xs = xp(idx)
         else
            xp(idx) = xs
         end if
      end subroutine move_l
   end subroutine submodel_transfer

   !> The clusters of m: its free nodes joined by links, mass couplings, stiffness blocks and
   !> the contacts j with joined(j) (closed ones), each element joining the free nodes of its
   !> row (a fixed node or the ground joins nothing: it does not move). label(i): node i's
   !> cluster, 1 … nclusters numbered in the order of their first node; 0 for a fixed node.
   !> Union-find with path halving over the elements' terms: O(n + terms).
   subroutine model_clusters(m, joined, label, nclusters)
      type(model_t), intent(in) :: m
      logical, intent(in) :: joined(:)
      integer, intent(out) :: label(:), nclusters
      integer :: j, first, i
      ! label holds the union-find parents first, then the cluster numbers
      label = [(i, i = 1, m%n)]
      do j = 1, m%nlink
         call join_row(m%lnk%node(m%lnk%first(j):m%lnk%first(j + 1) - 1))
      end do
      do j = 1, m%ncontact
         if (joined(j)) call join_row(m%con%node(m%con%first(j):m%con%first(j + 1) - 1))
      end do
      do j = 1, m%ncoupling
         call join_row([m%mc_a(j), m%mc_b(j)])
      end do
      do j = 1, m%nblock
         call join_row(m%block(j)%node)
      end do
      ! the root of a cluster is its smallest node (join_row keeps the smaller root), so the
      ! roots are met in node order before the other nodes of their clusters: numbered in one
      ! pass, negated while the others still hold their roots
      do i = 1, m%n
         label(i) = root(i)
      end do
      nclusters = 0
      do i = 1, m%n
         if (m%fixed(i)) then
            label(i) = 0
         else if (label(i) == i) then
            nclusters = nclusters + 1
            label(i) = -nclusters
         else
            label(i) = label(label(i))
         end if
      end do
      label = -label
   contains
      integer function root(i) result(r)
         integer, intent(in) :: i
         r = i
         do while (label(r) /= r)
            label(r) = label(label(r))        ! path halving
            r = label(r)
         end do
      end function root
      subroutine join_row(nd)
         integer, intent(in) :: nd(:)
         integer :: q, a, b
         first = 0
         do q = 1, size(nd)
            if (m%fixed(nd(q))) cycle
            if (first == 0) then
               first = nd(q); cycle
            end if
            a = root(first); b = root(nd(q))
            if (a /= b) label(max(a, b)) = min(a, b)   ! the smaller node is the root
         end do
      end subroutine join_row
   end subroutine model_clusters

   !> a in ascending order (heapsort: O(k log k) whatever the order given)
   subroutine sort_ints(a)
      integer, intent(inout) :: a(:)
      integer :: n, i, t
      n = size(a)
      do i = n/2, 1, -1
         call sift(i, n)
      end do
      do i = n, 2, -1
         t = a(1); a(1) = a(i); a(i) = t
         call sift(1, i - 1)
      end do
   contains
      subroutine sift(start, last)
         integer, intent(in) :: start, last
         integer :: r, c, t
         r = start
         do while (2*r <= last)
            c = 2*r
            if (c < last) then
               if (a(c + 1) > a(c)) c = c + 1
            end if
            if (a(r) >= a(c)) return
            t = a(r); a(r) = a(c); a(c) = t
            r = c
         end do
      end subroutine sift
   end subroutine sort_ints
end module martello_submodel
