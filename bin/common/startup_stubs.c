/* What lancer settles before the OCaml runtime starts.

   [lancer_startup] is a constructor: it runs before main, so before the runtime starts
   and before any library's initialisation opens a file or installs a handler. Report's
   initialisation ([lancer_startup_done]) ends what it begins, once lancer's own signal
   handlers are installed. */

#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

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

/* ---- Standard descriptors ----

   A descriptor among 0, 1 and 2 that is closed when lancer starts (lancer >&-) is opened
   on /dev/null in the direction that cannot be used: standard input write-only, standard
   output and error read-only. Every file lancer opens then gets a higher descriptor (a
   free 1 would be the next file's, and what is printed would go into it), and reading or
   writing them still fails as on a closed descriptor (EBADF), so that output lancer
   cannot deliver is reported, not lost. */

static int closed_at_start = 0; /* bit i: descriptor i was closed */

static void open_standard_descriptors(void)
{
  for (int fd = 0; fd <= 2; fd++) {
    if (fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    closed_at_start |= 1 << fd;
    int null = open("/dev/null", fd == 0 ? O_WRONLY : O_RDONLY);
    if (null >= 0 && null != fd) {
      dup2(null, fd);
      close(null);
    }
  }
}

__attribute__((constructor)) static void lancer_startup(void)
{
  block_stop_signals();
  open_standard_descriptors();
}

/* Report's handlers are in place: the signals held so far delivered to them. Returns
   which standard descriptors were closed at start (bit i for descriptor i). */
value lancer_startup_done(value unit)
{
  (void)unit;
  sigprocmask(SIG_SETMASK, &mask_at_start, NULL);
  return Val_int(closed_at_start);
}
