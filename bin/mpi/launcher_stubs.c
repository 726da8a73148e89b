/* What lancer-mpirun needs below OCaml's Unix: signal handlers that see who sent the
   signal (a terminal's Ctrl-C also reaches mpirun itself, a kill(2) may not), and a
   wait that gives the child's raw status. No MPI here. */

#define _GNU_SOURCE
#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <caml/fail.h>
#include <caml/mlvalues.h>

/* Set by the handler, read and cleared by the launcher's loop. */
static volatile sig_atomic_t interrupted = 0;
static volatile sig_atomic_t forward_int = 0;
static volatile sig_atomic_t forward_term = 0;
static volatile sig_atomic_t forward_hup = 0;

static void on_signal(int sig, siginfo_t *info, void *ctx)
{
  (void)ctx;
  interrupted = 1;
  switch (sig) {
  case SIGINT:
    /* A terminal's Ctrl-C (SI_KERNEL: sent by the tty to its whole foreground
       process group) has reached mpirun too; any other SIGINT may not have. */
    if (info == NULL || info->si_code != SI_KERNEL) forward_int = 1;
    break;
  case SIGTERM: forward_term = 1; break;
  case SIGHUP: forward_hup = 1; break;
  default: break;
  }
}

value lancer_mpirun_install(value unit)
{
  (void)unit;
  int sigs[] = { SIGINT, SIGTERM, SIGHUP };
  for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = on_signal;
    sa.sa_flags = SA_SIGINFO | SA_RESTART;
    sigemptyset(&sa.sa_mask);
    if (sigaction(sigs[i], &sa, NULL) != 0) caml_failwith("sigaction");
  }
  return Val_unit;
}

value lancer_mpirun_interrupted(value unit)
{
  (void)unit;
  return Val_bool(interrupted);
}

/* Passes the signals received since the last call that [pid] may not have received
   itself on to it, once each. */
value lancer_mpirun_forward(value pid)
{
  if (forward_int) { forward_int = 0; kill(Int_val(pid), SIGINT); }
  if (forward_term) { forward_term = 0; kill(Int_val(pid), SIGTERM); }
  if (forward_hup) { forward_hup = 0; kill(Int_val(pid), SIGHUP); }
  return Val_unit;
}

/* Without blocking: -1 while [pid] runs, its exit status once it has exited, 256 + the
   signal's number if a signal ended it. */
value lancer_mpirun_wait(value pid)
{
  int status;
  pid_t r;
  do r = waitpid(Int_val(pid), &status, WNOHANG);
  while (r < 0 && errno == EINTR);
  if (r == 0) return Val_int(-1);
  if (r < 0) caml_failwith(strerror(errno));
  if (WIFEXITED(status)) return Val_int(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return Val_int(256 + WTERMSIG(status));
  return Val_int(-1);
}
