/* What lancer settles before the OCaml runtime starts.

   [lancer_startup] is a constructor: it runs before main, so before the runtime starts
   and before any library's initialisation installs a handler. Report's initialisation
   ([lancer_startup_done]) ends what it begins, once lancer's own signal handlers are
   installed. */

#define _GNU_SOURCE
#include <signal.h>

#include <caml/mlvalues.h>

/* ---- Signals ----

   SIGINT and SIGTERM are blocked from the program's first moment until Report has
   installed its handlers: one that comes while the runtime and the libraries start is
   held pending, then delivered to those handlers (exit status 130), instead of ending
   the process by its default action. The mask lancer was started with is restored then
   (a signal its parent blocked stays blocked). Threads inherit the mask of the thread
   that creates them; none is created before the mask is restored.

   Before this constructor runs, the kernel and the dynamic loader load the program: no
   program can handle a signal there (its handlers are not installed yet), and one that
   comes then ends the process as it would end any other. */

static sigset_t mask_at_start;

static void block_stop_signals(void)
{
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  sigprocmask(SIG_BLOCK, &stop, &mask_at_start);
}

__attribute__((constructor)) static void lancer_startup(void)
{
  block_stop_signals();
}

/* Report's handlers are in place: the signals held so far delivered to them. */
value lancer_startup_done(value unit)
{
  (void)unit;
  sigprocmask(SIG_SETMASK, &mask_at_start, NULL);
  return Val_unit;
}
