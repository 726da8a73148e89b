/* Thin C stubs over Open MPI for lancer-mpi (see mpi.mli).

   Only MPI_COMM_WORLD is used, and only the main domain calls MPI (MPI_THREAD_FUNNELED).
   Every call that may block (send, receive, probe, barrier, broadcast) releases the
   OCaml runtime lock for its duration, so that the other domains of the process can
   run and collect garbage meanwhile. While the lock is released no OCaml heap value may
   be touched: bytes are copied into malloc'd buffers first (and out of them after), and
   Bigarray data, which lives outside the heap and does not move, is used in place while
   the Bigarray is held as a root.

   These stubs are built only where an MPI library was found (bin/mpi/discover.ml). */

#include <stdlib.h>
#include <string.h>

#include <caml/alloc.h>
#include <caml/bigarray.h>
#include <caml/fail.h>
#include <caml/memory.h>
#include <caml/mlvalues.h>
#include <caml/signals.h>

#include <mpi.h>

/* Raise [Failure] with MPI's text for [rc]. Call only while holding the runtime lock. */
static void check(int rc, const char *what)
{
  if (rc != MPI_SUCCESS) {
    char msg[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(rc, msg, &len);
    msg[len < MPI_MAX_ERROR_STRING ? len : MPI_MAX_ERROR_STRING - 1] = '\0';
    caml_failwith_value(caml_alloc_sprintf("MPI %s: %s", what, msg));
  }
}

static int source_of(value v) { return Int_val(v) < 0 ? MPI_ANY_SOURCE : Int_val(v); }
static int tag_of(value v) { return Int_val(v) < 0 ? MPI_ANY_TAG : Int_val(v); }

/* A tuple of three ints. */
static value triple(int source, int tag, int count)
{
  value r = caml_alloc_tuple(3);
  Store_field(r, 0, Val_int(source));
  Store_field(r, 1, Val_int(tag));
  Store_field(r, 2, Val_int(count));
  return r;
}


value lancer_mpi_init(value unit)
{
  int flag = 0, provided = 0;
  MPI_Initialized(&flag);
  if (flag) return Val_unit;
  /* No arguments: Open MPI takes what it needs from the environment mpirun sets. */
  check(MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided), "Init_thread");
  if (provided < MPI_THREAD_FUNNELED) caml_failwith("MPI: this MPI library does not provide MPI_THREAD_FUNNELED");
  return Val_unit;
}

value lancer_mpi_initialized(value unit)
{
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  return Val_bool(init && !fin);
}

value lancer_mpi_finalize(value unit)
{
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  if (init && !fin) {
    int rc;
    caml_enter_blocking_section();
    rc = MPI_Finalize();
    caml_leave_blocking_section();
    check(rc, "Finalize");
  }
  return Val_unit;
}

value lancer_mpi_rank(value unit)
{
  int r = 0;
  check(MPI_Comm_rank(MPI_COMM_WORLD, &r), "Comm_rank");
  return Val_int(r);
}

value lancer_mpi_size(value unit)
{
  int s = 0;
  check(MPI_Comm_size(MPI_COMM_WORLD, &s), "Comm_size");
  return Val_int(s);
}

value lancer_mpi_barrier(value unit)
{
  int rc;
  caml_enter_blocking_section();
  rc = MPI_Barrier(MPI_COMM_WORLD);
  caml_leave_blocking_section();
  check(rc, "Barrier");
  return Val_unit;
}

value lancer_mpi_abort(value code)
{
  int init = 0, fin = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&fin);
  /* Before MPI_Init or after MPI_Finalize, MPI_Abort may not be called: just exit. */
  if (init && !fin) MPI_Abort(MPI_COMM_WORLD, Int_val(code));
  exit(Int_val(code)); /* not reached: MPI_Abort does not return */
}

value lancer_mpi_wtime(value unit) { return caml_copy_double(MPI_Wtime()); }

value lancer_mpi_send_bytes(value buf, value dest, value tag)
{
  CAMLparam3(buf, dest, tag);
  int n = caml_string_length(buf), d = Int_val(dest), t = Int_val(tag), rc;
  char *copy = malloc(n > 0 ? n : 1);
  if (copy == NULL) caml_raise_out_of_memory();
  memcpy(copy, Bytes_val(buf), n);
  caml_enter_blocking_section();
  rc = MPI_Send(copy, n, MPI_BYTE, d, t, MPI_COMM_WORLD);
  free(copy);
  caml_leave_blocking_section();
  check(rc, "Send");
  CAMLreturn(Val_unit);
}

/* Matched probe then receive, so that the message sized is the message received. */
value lancer_mpi_recv_bytes(value source, value tag)
{
  CAMLparam2(source, tag);
  CAMLlocal2(buf, r);
  int s = source_of(source), t = tag_of(tag), rc, n = 0;
  char *data = NULL;
  MPI_Message msg;
  MPI_Status st;
  caml_enter_blocking_section();
  rc = MPI_Mprobe(s, t, MPI_COMM_WORLD, &msg, &st);
  if (rc == MPI_SUCCESS) rc = MPI_Get_count(&st, MPI_BYTE, &n);
  if (rc == MPI_SUCCESS) {
    data = malloc(n > 0 ? n : 1);
    if (data == NULL) rc = MPI_ERR_NO_MEM;
    else rc = MPI_Mrecv(data, n, MPI_BYTE, &msg, &st);
  }
  caml_leave_blocking_section();
  if (rc != MPI_SUCCESS) {
    free(data);
    check(rc, "Recv");
  }
  buf = caml_alloc_string(n);
  memcpy(Bytes_val(buf), data, n);
  free(data);
  r = caml_alloc_tuple(3);
  Store_field(r, 0, buf);
  Store_field(r, 1, Val_int(st.MPI_SOURCE));
  Store_field(r, 2, Val_int(st.MPI_TAG));
  CAMLreturn(r);
}

/* Every rank passes a buffer; the root's is sent. The length goes first. */
value lancer_mpi_bcast_bytes(value buf, value root)
{
  CAMLparam2(buf, root);
  CAMLlocal1(r);
  int me = 0, rt = Int_val(root), rc, n = 0;
  char *data = NULL;
  check(MPI_Comm_rank(MPI_COMM_WORLD, &me), "Comm_rank");
  if (me == rt) {
    n = caml_string_length(buf);
    data = malloc(n > 0 ? n : 1);
    if (data == NULL) caml_raise_out_of_memory();
    memcpy(data, Bytes_val(buf), n);
  }
  caml_enter_blocking_section();
  rc = MPI_Bcast(&n, 1, MPI_INT, rt, MPI_COMM_WORLD);
  if (rc == MPI_SUCCESS && me != rt) {
    data = malloc(n > 0 ? n : 1);
    if (data == NULL) rc = MPI_ERR_NO_MEM;
  }
  if (rc == MPI_SUCCESS) rc = MPI_Bcast(data, n, MPI_BYTE, rt, MPI_COMM_WORLD);
  caml_leave_blocking_section();
  if (rc != MPI_SUCCESS) {
    free(data);
    check(rc, "Bcast");
  }
  r = caml_alloc_string(n);
  memcpy(Bytes_val(r), data, n);
  free(data);
  CAMLreturn(r);
}

value lancer_mpi_send_floats(value ba, value len, value dest, value tag)
{
  CAMLparam4(ba, len, dest, tag);
  double *data = (double *)Caml_ba_data_val(ba);
  int n = Int_val(len), d = Int_val(dest), t = Int_val(tag), rc;
  if (n < 0 || (intnat)n > Caml_ba_array_val(ba)->dim[0]) caml_invalid_argument("Mpi.send_floats: length");
  caml_enter_blocking_section();
  rc = MPI_Send(data, n, MPI_DOUBLE, d, t, MPI_COMM_WORLD);
  caml_leave_blocking_section();
  check(rc, "Send");
  CAMLreturn(Val_unit);
}

value lancer_mpi_recv_floats(value ba, value source, value tag)
{
  CAMLparam3(ba, source, tag);
  double *data = (double *)Caml_ba_data_val(ba);
  intnat cap = Caml_ba_array_val(ba)->dim[0];
  int s = source_of(source), t = tag_of(tag), rc, n = 0;
  MPI_Message msg;
  MPI_Status st;
  caml_enter_blocking_section();
  rc = MPI_Mprobe(s, t, MPI_COMM_WORLD, &msg, &st);
  if (rc == MPI_SUCCESS) rc = MPI_Get_count(&st, MPI_DOUBLE, &n);
  /* A message too long for the buffer is received into nothing, then reported. */
  if (rc == MPI_SUCCESS) rc = MPI_Mrecv(n <= cap ? data : NULL, n <= cap ? n : 0, MPI_DOUBLE, &msg, &st);
  caml_leave_blocking_section();
  if (rc == MPI_SUCCESS && n > cap) caml_invalid_argument("Mpi.recv_floats: message longer than the buffer");
  check(rc, "Recv");
  CAMLreturn(triple(n, st.MPI_SOURCE, st.MPI_TAG));
}

value lancer_mpi_probe(value source, value tag)
{
  CAMLparam2(source, tag);
  int s = source_of(source), t = tag_of(tag), rc, n = 0;
  MPI_Status st;
  caml_enter_blocking_section();
  rc = MPI_Probe(s, t, MPI_COMM_WORLD, &st);
  if (rc == MPI_SUCCESS) rc = MPI_Get_count(&st, MPI_BYTE, &n);
  caml_leave_blocking_section();
  check(rc, "Probe");
  CAMLreturn(triple(st.MPI_SOURCE, st.MPI_TAG, n));
}

value lancer_mpi_iprobe(value source, value tag)
{
  CAMLparam2(source, tag);
  CAMLlocal1(r);
  int s = source_of(source), t = tag_of(tag), flag = 0, n = 0;
  MPI_Status st;
  check(MPI_Iprobe(s, t, MPI_COMM_WORLD, &flag, &st), "Iprobe");
  if (!flag) CAMLreturn(Val_none);
  check(MPI_Get_count(&st, MPI_BYTE, &n), "Get_count");
  r = triple(st.MPI_SOURCE, st.MPI_TAG, n);
  CAMLreturn(caml_alloc_some(r));
}


