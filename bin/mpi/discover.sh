#!/bin/sh
# Reads Open MPI's compile and link flags for the C stubs from the installed mpicc.
# Without mpicc the stubs are built without MPI (every call then fails with a clear
# message), so the rest of lancer builds and the MPI tests skip themselves.
# Writes c_flags.sexp and c_library_flags.sexp in the current directory.
set -u
if command -v mpicc >/dev/null 2>&1 \
   && cflags=$(mpicc --showme:compile 2>/dev/null) \
   && libs=$(mpicc --showme:link 2>/dev/null); then
  printf '(-DLANCER_HAVE_MPI %s)\n' "$cflags" > c_flags.sexp
  printf '(%s)\n' "$libs" > c_library_flags.sexp
else
  printf '()\n' > c_flags.sexp
  printf '()\n' > c_library_flags.sexp
fi
