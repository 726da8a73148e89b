/* What lancer settles before the OCaml runtime starts, and the runtime's fatal errors in
   lancer's words.

   [lancer_startup] is a constructor: it runs before main, so before the runtime parses
   OCAMLRUNPARAM and reserves memory, and before any library's initialisation opens a
   file or installs a handler. Report's initialisation ([lancer_startup_done]) ends what
   it begins, once lancer's own signal handlers are installed. */

#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <malloc.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include <caml/alloc.h>
#include <caml/misc.h>
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

/* ---- Address space ----

   OCaml 5's runtime reserves, as it starts, address space for the minor heaps of as many
   domains as it may ever run: 128 by default, 2 MiB each, 256 MiB in all. Reserved
   space is free until used, unless the address space is limited (ulimit -v): then the
   reservation alone takes 256 MiB of the limit, the runtime cannot start under it
   ("Not enough heap memory to reserve minor heaps"), and just above it little is left
   for the scene and the image.

   Under a limit, and unless OCAMLRUNPARAM sets the number of domains (d) itself, the
   reservation is made for no more domains than the limit could run anyway: a domain
   also needs the stacks of its two threads (its own and the runtime's backup thread),
   so [limit / (minor heap + 2 stacks)] domains at most, which keeps the reservation to
   a small share of the limit. OCAMLRUNPARAM is set for the runtime to read and restored
   by [lancer_startup_done], so that the programs lancer runs see the environment it was
   given.

   glibc's malloc also gives threads arenas of their own, each reserving 64 MiB: under a
   limit there are only as many as take an eighth of it (as the minor heaps do), one at
   least, so that the limit goes to the scene and the image. MALLOC_ARENA_MAX or a malloc
   tunable in GLIBC_TUNABLES overrides this. */

#define MIB (1024UL * 1024UL)
#define MAX_DOMAINS_DEFAULT 128UL
#define MINOR_HEAP_WORDS_DEFAULT 262144UL
#define ARENA_BYTES (64UL * MIB)

static char *runparam_saved = NULL; /* OCAMLRUNPARAM as lancer got it */
static int runparam_was_set = 0;
static int runparam_changed = 0;

/* Where option [letter] starts in an OCAMLRUNPARAM value ("b,s=4M,d=8"), or NULL: the
   runtime reads the letter at the start of each comma-separated item. */
static const char *runparam_option(const char *opt, char letter)
{
  const char *p = opt;
  while (p != NULL && *p != '\0') {
    if (*p == letter) return p;
    p = strchr(p, ',');
    if (p != NULL) p++;
  }
  return NULL;
}

/* A size as the runtime reads it: "=N" with an optional k, M or G multiplier. */
static unsigned long runparam_size(const char *item, unsigned long def)
{
  char *end;
  if (item[1] != '=') return def;
  errno = 0;
  unsigned long v = strtoul(item + 2, &end, 0);
  if (errno != 0 || end == item + 2) return def;
  switch (*end) {
  case 'k': return v * 1024UL;
  case 'M': return v * MIB;
  case 'G': return v * 1024UL * MIB;
  default: return v;
  }
}

static size_t thread_stack_bytes(void)
{
  pthread_attr_t attr;
  size_t size = 8 * MIB;
  if (pthread_getattr_default_np(&attr) == 0) {
    pthread_attr_getstacksize(&attr, &size);
    pthread_attr_destroy(&attr);
  }
  return size;
}

static void fit_address_space(void)
{
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return;
  unsigned long limit = rl.rlim_cur;

  /* The runtime reads CAMLRUNPARAM when OCAMLRUNPARAM is not set. */
  const char *own = getenv("OCAMLRUNPARAM");
  const char *opt = own != NULL ? own : getenv("CAMLRUNPARAM");
  if (opt == NULL) opt = "";
  runparam_was_set = own != NULL;
  if (runparam_option(opt, 'd') == NULL) {
    const char *s = runparam_option(opt, 's');
    unsigned long words = MINOR_HEAP_WORDS_DEFAULT;
    if (s != NULL) words = runparam_size(s, words);
    unsigned long minor = words * sizeof(value);
    unsigned long domains = limit / (minor + 2 * thread_stack_bytes());
    if (domains < 1) domains = 1;
    if (domains < MAX_DOMAINS_DEFAULT) {
      size_t n = strlen(opt) + 32;
      char *v = malloc(n);
      if (v != NULL) {
        snprintf(v, n, "%s%sd=%lu", opt, *opt != '\0' ? "," : "", domains);
        if (own != NULL) runparam_saved = strdup(own);
        if (setenv("OCAMLRUNPARAM", v, 1) == 0) runparam_changed = 1;
        free(v);
      }
    }
  }

  const char *tunables = getenv("GLIBC_TUNABLES");
  if (getenv("MALLOC_ARENA_MAX") == NULL
      && (tunables == NULL || strstr(tunables, "glibc.malloc.arena") == NULL)) {
    unsigned long arenas = limit / 8 / ARENA_BYTES;
    mallopt(M_ARENA_MAX, arenas < 1 ? 1 : (int)arenas);
  }
}

static void restore_runparam(void)
{
  if (!runparam_changed) return;
  if (runparam_was_set && runparam_saved != NULL)
    setenv("OCAMLRUNPARAM", runparam_saved, 1);
  else if (!runparam_was_set)
    unsetenv("OCAMLRUNPARAM");
  free(runparam_saved);
  runparam_saved = NULL;
  runparam_changed = 0;
}

/* ---- The runtime's fatal errors ----

   The runtime ends the process with "Fatal error: …" and abort() when it cannot go on:
   most often because memory ran out where it cannot raise Out_of_memory (reserving the
   minor heaps, a minor collection, a new domain's stacks). Those are said as lancer
   says out of memory, with status 1; anything else is an internal error, status 2 (as
   Report says them), and a bad OCAMLRUNPARAM is the user's, status 1. The process
   ends with _exit: no OCaml code can run from here. */

static int is_memory_failure(const char *text)
{
  static const char *const words[] = { "memory", "alloc", "Alloc", "reserve",
                                       "signal stack", "mmap", "Failed to create",
                                       "Cannot allocate" };
  for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
    if (strstr(text, words[i]) != NULL) return 1;
  return 0;
}

static void say(const char *text)
{
  size_t n = strlen(text);
  while (n > 0) {
    ssize_t w = write(2, text, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;
    text += w;
    n -= (size_t)w;
  }
}

/* The out-of-memory line, the same as Report's: with the limit and what to try. */
static void out_of_memory_text(char *buf, size_t n)
{
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
    snprintf(buf, n,
             "lancer: out of memory under the address-space limit (ulimit -v %lu); "
             "raise it, or try a smaller image, fewer objects or fewer --domains\n",
             (unsigned long)(rl.rlim_cur / 1024UL));
  else
    snprintf(buf, n, "lancer: out of memory (try a smaller image or fewer objects)\n");
}

static void lancer_fatal_error(char *msg, va_list args)
{
  char what[512], text[1024];
  vsnprintf(what, sizeof what, msg, args);
  if (is_memory_failure(what)) {
    out_of_memory_text(text, sizeof text);
    say(text);
    _exit(1);
  }
  if (strncmp(what, "OCAMLRUNPARAM", 13) == 0) {
    snprintf(text, sizeof text, "lancer: %s\n", what);
    say(text);
    _exit(1);
  }
  snprintf(text, sizeof text,
           "lancer: internal error: %s\n"
           "This is a bug in lancer; please report it with the scene and the command.\n",
           what);
  say(text);
  _exit(2);
}

__attribute__((constructor)) static void lancer_startup(void)
{
  block_stop_signals();
  open_standard_descriptors();
  caml_fatal_error_hook = lancer_fatal_error;
  fit_address_space();
}

/* Report's handlers are in place: the environment as lancer got it, and the signals
   held so far delivered to the handlers. Returns which standard descriptors were
   closed at start (bit i for descriptor i). */
value lancer_startup_done(value unit)
{
  (void)unit;
  restore_runparam();
  sigprocmask(SIG_SETMASK, &mask_at_start, NULL);
  return Val_int(closed_at_start);
}

/* The out-of-memory line, for Report. */
value lancer_out_of_memory_text(value unit)
{
  (void)unit;
  char text[512];
  out_of_memory_text(text, sizeof text);
  return caml_copy_string(text);
}
