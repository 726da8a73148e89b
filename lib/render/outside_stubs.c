/* Float arrays outside the OCaml heap, freed when their owner is done with them
   (Gathered's held floats): the collector neither counts nor frees their memory. */
#include <stdlib.h>
#include <caml/mlvalues.h>
#include <caml/memory.h>
#include <caml/fail.h>
#include <caml/bigarray.h>

/* A float64 array of [n] floats (uninitialised), its memory outside the heap: the
   bigarray is external, so that it does not hurry the collector as managed memory of its
   size would. */
value lancer_outside_create(value vn)
{
  CAMLparam1(vn);
  CAMLlocal1(ba);
  static double none;
  intnat n = Long_val(vn);
  intnat dim[1];
  dim[0] = 0;
  /* The array first, empty, so that nothing is lost if its allocation raises; then its
     memory, so that an array whose memory could not be had holds none. */
  ba = caml_ba_alloc(CAML_BA_FLOAT64 | CAML_BA_C_LAYOUT | CAML_BA_EXTERNAL, 1, &none, dim);
  struct caml_ba_array *b = Caml_ba_array_val(ba);
  b->data = NULL;
  double *data = malloc((n > 0 ? (size_t)n : 1) * sizeof(double));
  if (data == NULL) caml_raise_out_of_memory();
  b->data = data;
  b->dim[0] = n;
  CAMLreturn(ba);
}

/* Frees the memory of an array [lancer_outside_create] made and leaves it empty (no
   element, no data); a second call does nothing. */
value lancer_outside_release(value ba)
{
  struct caml_ba_array *b = Caml_ba_array_val(ba);
  if (b->data != NULL) {
    free(b->data);
    b->data = NULL;
    b->dim[0] = 0;
  }
  return Val_unit;
}
