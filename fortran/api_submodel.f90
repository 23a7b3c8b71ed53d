!> The C door of sub-models (c/martello_internal.h, martello_model_subset and
!> martello_eval_state_transfer; docs/run-layer.md, "Sub-models for local stepping"): 0-based
!> C numbers ↔ the kernels' 1-based ones, the map's arrays in C's heap (the C caller frees them with
!> martello_subset_map_free). Nothing is computed here (martello_submodel).
module martello_api_submodel
   use, intrinsic :: iso_c_binding
   use martello_kinds, only: dp
   use martello_status
   use martello_model, only: model_t, model_expand_chains
   use martello_evaluator, only: evaluator_t
   use martello_submodel, only: submodel_map_t, submodel_build, submodel_transfer, model_clusters
   use martello_api_handles, only: get_model, get_eval
   implicit none
   private

   !> martello_subset_map of c/martello_internal.h
   type, bind(C) :: subset_map_c
      integer(c_int) :: n_nodes = 0, n_links = 0, n_contacts = 0
      type(c_ptr) :: node = c_null_ptr, link = c_null_ptr, contact = c_null_ptr
      integer(c_int) :: n_blocks = 0
      type(c_ptr) :: block = c_null_ptr
   end type subset_map_c

   interface
      type(c_ptr) function c_malloc(bytes) bind(C, name='malloc')
         import :: c_ptr, c_size_t
         integer(c_size_t), value :: bytes
      end function c_malloc
      subroutine c_free(p) bind(C, name='free')
         import :: c_ptr
         type(c_ptr), value :: p
      end subroutine c_free
   end interface

contains

   !> The sub-model of parent on the free nodes nodes[0 … n−1] (submodel_build); sub is freed
   !> by martello_model_free, map's arrays by martello_subset_map_free (map is zeroed first:
   !> freeing it after a failure is safe).
   integer(c_int) function c_model_subset(parent, n, nodes, sub, map) &
      bind(C, name='martello_model_subset')
      type(c_ptr), value :: parent
      integer(c_int), value :: n
      integer(c_int), intent(in) :: nodes(*)
      type(c_ptr), intent(out) :: sub
      type(subset_map_c), intent(out) :: map
      type(model_t), pointer :: pm, sm
      type(submodel_map_t) :: fmap
      integer :: stat
      sub = c_null_ptr
      map = subset_map_c()
      c_model_subset = MARTELLO_ERR_ARGUMENT
      pm => get_model(parent)
      if (.not. associated(pm)) return
      if (n < 1) then
         pm%errmsg = 'model_subset: n must be >= 1 (a cluster has at least one free node)'; return
      end if
      allocate (sm, stat=stat)
      if (stat /= 0) then
         c_model_subset = MARTELLO_ERR_MEMORY; return
      end if
      call submodel_build(pm, nodes(1:n) + 1, sm, fmap, stat)
      if (stat == MARTELLO_OK) then
         map%node = c_array(fmap%node, map%n_nodes, stat)
         map%link = c_array(fmap%link, map%n_links, stat)
         map%contact = c_array(fmap%contact, map%n_contacts, stat)
         map%block = c_array(fmap%block, map%n_blocks, stat)
         if (stat /= MARTELLO_OK) then
            call c_subset_map_free(map)
            call out_of_memory('a sub-model''s map', 4.0_dp*(size(fmap%node) + size(fmap%link) &
                               + size(fmap%contact) + size(fmap%block)), FIX_SMALLER_SCENE, &
                               stat, pm%errmsg)
         end if
      end if
      if (stat /= MARTELLO_OK) then
         deallocate (sm)
         c_model_subset = stat; return
      end if
      sub = c_loc(sm)
      c_model_subset = MARTELLO_OK
   contains
      !> x − 1 in a malloc'ed C array (at least one element: malloc(0) may be NULL); count ← size
      type(c_ptr) function c_array(x, count, stat) result(p)
         integer, intent(in) :: x(:)
         integer(c_int), intent(out) :: count
         integer, intent(inout) :: stat
         integer(c_int), pointer :: a(:)
         count = size(x)
         p = c_malloc(int(max(1, size(x)), c_size_t)*c_sizeof(0_c_int))
         if (.not. c_associated(p)) then
            stat = MARTELLO_ERR_MEMORY; return
         end if
         call c_f_pointer(p, a, [max(1, size(x))])
         a(1:size(x)) = x - 1
      end function c_array
   end function c_model_subset

   !> Free map's arrays (malloc'ed by martello_model_subset) and zero it.
   subroutine c_subset_map_free(map) bind(C, name='martello_subset_map_free')
      type(subset_map_c), intent(inout) :: map
      if (c_associated(map%node)) call c_free(map%node)
      if (c_associated(map%link)) call c_free(map%link)
      if (c_associated(map%contact)) call c_free(map%contact)
      if (c_associated(map%block)) call c_free(map%block)
      map = subset_map_c()
   end subroutine c_subset_map_free

   !> The model's chains made into links and contacts one by one, in place
   !> (model_expand_chains): what martello_model_subset takes.
   integer(c_int) function c_model_expand_chains(handle) bind(C, name='martello_model_expand_chains')
      type(c_ptr), value :: handle
      type(model_t), pointer :: mp
      integer :: stat
      character(len=512) :: message
      mp => get_model(handle)
      c_model_expand_chains = MARTELLO_ERR_ARGUMENT
      if (.not. associated(mp)) return
      message = ''
      call model_expand_chains(mp, stat, message)
      if (stat /= MARTELLO_OK) mp%errmsg = message
      c_model_expand_chains = stat
   end function c_model_expand_chains

   !> The clusters of the model's free nodes (model_clusters): joined[j] /= 0 for a contact that
   !> joins its nodes (NULL: none does); label[i] the cluster of node i, 0 … *n_clusters − 1 in
   !> the order of their first node, −1 for a fixed node.
   integer(c_int) function c_model_clusters(handle, joined, label, n_clusters) &
      bind(C, name='martello_model_clusters')
      type(c_ptr), value :: handle, joined
      integer(c_int), intent(out) :: label(*), n_clusters
      type(model_t), pointer :: mp
      integer(c_int), pointer :: pj(:)
      logical, allocatable :: join(:)
      integer, allocatable :: lab(:)
      integer :: nc, st
      n_clusters = 0
      c_model_clusters = MARTELLO_ERR_ARGUMENT
      mp => get_model(handle)
      if (.not. associated(mp)) return
      if (mp%nchain > 0) then
         mp%errmsg = 'model_clusters: the model holds chains per node (model_add_chain);'// &
                     ' call martello_model_expand_chains first'; return
      end if
      nc = mp%ncontact
      allocate (join(nc), lab(mp%n), stat=st)
      if (st /= 0) then
         call out_of_memory('the clusters of a model', 4.0_dp*(nc + mp%n), FIX_SMALLER_SCENE, &
                            st, mp%errmsg)
         c_model_clusters = st; return
      end if
      join = .false.
      if (c_associated(joined) .and. nc > 0) then
         call c_f_pointer(joined, pj, [nc])
         join = pj /= 0
      end if
      call model_clusters(mp, join, lab, st)
      label(1:mp%n) = lab - 1
      n_clusters = st
      c_model_clusters = MARTELLO_OK
   end function c_model_clusters

   !> The elements' and nodes' state of map between the parent's evaluator and the sub-model's
   !> (submodel_transfer): to_sub /= 0 parent → sub, 0 sub → parent.
   integer(c_int) function c_eval_state_transfer(parent, sub, map, to_sub) &
      bind(C, name='martello_eval_state_transfer')
      type(c_ptr), value :: parent, sub
      type(subset_map_c), intent(in) :: map
      integer(c_int), value :: to_sub
      type(evaluator_t), pointer :: pe, se
      type(submodel_map_t) :: fmap
      integer :: stat
      c_eval_state_transfer = MARTELLO_ERR_ARGUMENT
      pe => get_eval(parent); se => get_eval(sub)
      if (.not. (associated(pe) .and. associated(se))) return
      if (min(map%n_nodes, map%n_links, map%n_contacts, map%n_blocks) < 0) then
         pe%m%errmsg = 'eval_state_transfer: the map''s counts must be >= 0 (a map that'// &
                       ' martello_model_subset filled)'; return
      end if
      fmap%node = f_array(map%node, map%n_nodes, stat)
      if (stat == 0) fmap%link = f_array(map%link, map%n_links, stat)
      if (stat == 0) fmap%contact = f_array(map%contact, map%n_contacts, stat)
      if (stat == 0) fmap%block = f_array(map%block, map%n_blocks, stat)
      if (stat /= 0) then
         pe%m%errmsg = 'eval_state_transfer: a map array is NULL (a map that'// &
                       ' martello_model_subset filled, not yet freed)'; return
      end if
      call submodel_transfer(pe, se, fmap, to_sub /= 0, stat)
      c_eval_state_transfer = stat
   contains
      !> the C array p of count 0-based numbers, 1-based; stat 1 for a NULL p
      function f_array(p, count, stat) result(x)
         type(c_ptr), intent(in) :: p
         integer(c_int), intent(in) :: count
         integer, intent(out) :: stat
         integer, allocatable :: x(:)
         integer(c_int), pointer :: a(:)
         stat = 0
         if (.not. c_associated(p)) then
            stat = 1; allocate (x(0)); return
         end if
         call c_f_pointer(p, a, [max(1, int(count))])
         x = a(1:count) + 1
      end function f_array
   end function c_eval_state_transfer
end module martello_api_submodel
