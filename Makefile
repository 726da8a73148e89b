# lancer — the two commands a newcomer needs are `make demo` and `make test`;
# each installs what is missing first (`make deps`, see .ci/toolchain and the README).
# Every dune command runs through .ci/toolchain: natively where OCaml 5 is installed,
# otherwise inside the project-local Debian 13 root in _toolchain/.

DUNE ?= dune
JOBS ?= 2
RUN := bash .ci/toolchain run
PREFIX ?= $(HOME)/.local


.PHONY: all deps deps-build deps-install build demo test golden-update bench bench-povray bench-limit bench-mpi bench-watch bench-budget fuzz doc clean \
	clean-toolchain fmt install uninstall static cluster-bundle flip-oracle packages

all: build

deps:
	@bash .ci/toolchain setup

# What building lancer needs, without what only its tests need (Open MPI, Chromium, …).
deps-build:
	@bash .ci/toolchain setup --build

# What make install builds: the build set, alcotest (for lancer-alcotest), and in the
# toolchain root Open MPI (for lancer-mpi).
deps-install:
	@bash .ci/toolchain setup --install

# lancer and lancer-mpi (where an MPI library is found), not lancer-alcotest: its
# library needs alcotest, which only the tests and make install (deps-install) install.
build: deps-build
	$(RUN) $(DUNE) build -j $(JOBS) --only-packages lancer,lancer-mpi @install

# A lancer that runs on this machine itself: the dynamically linked one where the
# toolchain is native, the statically linked one when it was built in the toolchain root
# (whose C library is newer than the host's).
static: deps-build
	$(RUN) env LANCER_STATIC=1 $(DUNE) build -j $(JOBS) bin/static/lancer_static.exe

out/bin/lancer: build
	@mkdir -p out/bin
	@if [ "$$(bash .ci/toolchain mode)" = root ]; then \
	  $(MAKE) --no-print-directory static && \
	  install -m 0755 _build/default/bin/static/lancer_static.exe out/bin/lancer && \
	  $(RUN) strip out/bin/lancer; \
	else install -m 0755 _build/default/bin/main.exe out/bin/lancer; fi

demo: out/bin/lancer
	out/bin/lancer render scenes/showcase.rts -o out/showcase.png
	out/bin/lancer animate scenes/bounce.rts -o out/bounce --width 320 --height 180
	@echo "The showcase is in out/showcase.png; the frames of a bouncing ball are in out/bounce/"
	@command -v ffmpeg >/dev/null 2>&1 && out/bin/lancer animate scenes/bounce.rts -o out/bounce --width 320 --height 180 --resume --video out/bounce.gif -q && echo "and as a GIF in out/bounce.gif" || true
	@echo "lancer itself is out/bin/lancer: run 'make install' to put it in $(PREFIX)/bin"

# lancer, lancer's man pages and shell completion, and its scene library (dsl/lancer/,
# installed as share/lancer/), under DESTDIR/PREFIX (PREFIX default ~/.local); the
# statically linked lancer is stripped of its debugging information. Then the libraries
# lancer, lancer-alcotest and lancer-mpi (lib/, for a dune project of one's own) and
# lancer-env, which runs a command with the toolchain they were built with and them on
# OCAMLPATH (.ci/lancer-env). lancer-mpi and lancer-mpirun where they were built: as
# they are where the toolchain is native; in the toolchain root (whose C and MPI
# libraries are Debian 13's) under libexec/lancer/, with lancer-env's wrappers in bin/
# that run them in the root.
DEST = $(DESTDIR)$(PREFIX)
MAN1 = $(DEST)/share/man/man1
LIBS = lancer lancer-alcotest lancer-mpi
install: deps-install out/bin/lancer
	$(RUN) $(DUNE) build -j $(JOBS) --only-packages lancer,lancer-alcotest,lancer-mpi @install
	install -d $(DEST)/bin $(MAN1) $(DEST)/share/bash-completion/completions $(DEST)/share/lancer
	install -m 0755 out/bin/lancer $(DEST)/bin/lancer
	install -m 0644 _build/default/bin/share/*.1 $(MAN1)/
	install -m 0644 _build/default/bin/share/lancer.bash $(DEST)/share/bash-completion/completions/lancer
	install -m 0644 dsl/lancer/materials.rts dsl/lancer/colors.rts $(DEST)/share/lancer/
	@mode=$$(bash .ci/install-env _build/install/default/lib $(DEST) $(PREFIX)) || exit 1; \
	if [ -x _build/default/bin/mpi/lancer_mpi_main.exe ]; then \
	  if [ "$$mode" = root ]; then bin=$(DEST)/libexec/lancer; else bin=$(DEST)/bin; fi; \
	  install -d $$bin && \
	  install -m 0755 _build/default/bin/mpi/lancer_mpi_main.exe $$bin/lancer-mpi && \
	  install -m 0755 _build/default/bin/mpi/lancer_mpirun.exe $$bin/lancer-mpirun && \
	  if [ "$$mode" = root ]; then \
	    install -m 0755 $(DEST)/bin/lancer-env $(DEST)/bin/lancer-mpi && \
	    install -m 0755 $(DEST)/bin/lancer-env $(DEST)/bin/lancer-mpirun; fi && \
	  install -m 0644 _build/default/bin/mpi/*.1 $(MAN1)/ && \
	  echo "installed lancer-mpi and lancer-mpirun"; fi
	@echo "installed $(DEST)/bin/lancer, its man pages, bash completion and scene library ($(DEST)/share/lancer/)"
	@echo "installed the libraries $(LIBS) in $(DEST)/lib/ and lancer-env: 'lancer-env dune test' in a project of yours"
	@case ":$$PATH:" in *":$(PREFIX)/bin:"*) ;; *) echo "add $(PREFIX)/bin to your PATH to run it as lancer";; esac

# Everything install put there, and the directories it made that are left empty.
uninstall:
	rm -f $(DEST)/bin/lancer $(DEST)/bin/lancer-env $(DEST)/bin/lancer-mpi $(DEST)/bin/lancer-mpirun \
	  $(MAN1)/lancer.1 $(MAN1)/lancer-*.1 \
	  $(DEST)/share/bash-completion/completions/lancer \
	  $(DEST)/share/lancer/materials.rts $(DEST)/share/lancer/colors.rts \
	  $(DEST)/lib/stublibs/dlllancer_*.so
	rm -rf $(addprefix $(DEST)/lib/,$(LIBS)) $(DEST)/libexec/lancer
	@for d in share/lancer share/bash-completion/completions share/bash-completion \
	  share/man/man1 share/man share lib/stublibs lib libexec bin; do \
	  rmdir $(DEST)/$$d 2>/dev/null || true; done

test: deps
	$(RUN) $(DUNE) build -j $(JOBS) @install
	$(RUN) $(DUNE) test -j $(JOBS) --force

# FLIP and SSIM against the reference implementations, the table of test/flip remade
# from them (pip installs them into out/ the first time).
flip-oracle: deps
	bash test/flip/oracle.sh
# Each of the three packages built and tested on its own, as opam does it: lancer, then
# lancer-alcotest and lancer-mpi against the installed lancer (.ci/packages).
packages: deps
	$(RUN) env JOBS=$(JOBS) bash .ci/packages

# Re-render every golden image from its scene. Only this command changes goldens.
golden-update: build
	$(RUN) env LANCER_UPDATE_GOLDEN=1 $(DUNE) test -j $(JOBS) --force test/golden

# The user's measures (lancer bench) and the developers' benchmarks (bench/lancer_bench.exe,
# not installed).
bench: build
	$(RUN) $(DUNE) build -j $(JOBS) ./bench/lancer_bench.exe
	$(RUN) ./_build/default/bench/lancer_bench.exe scaling --counts 1000,10000,100000,1000000
	$(RUN) $(DUNE) exec --no-build -- lancer bench domains --width 1920 --height 1080 --counts 1,2
	$(RUN) $(DUNE) exec --no-build -- lancer bench domains scenes/bench/three_spheres.rts --counts 1 --repeat 1
	$(RUN) ./_build/default/bench/lancer_bench.exe physics
	$(RUN) $(DUNE) exec --no-build -- lancer bench animation scenes/bench/field_moving.rts
	$(RUN) ./_build/default/bench/lancer_bench.exe language

# lancer watch: from a save of the showcase (640×480) to the first and to the full image.
# --max-error 0.02 on every gallery scene at 640×480 against a reference render: the
# table of doc/explanation/speed.md, "An error budget" (bench/budget.sh; knobs W, H, E,
# DOMAINS, REPEAT, SCENES).
bench-budget: build
	$(RUN) bash bench/budget.sh

bench-watch: build
	$(RUN) $(DUNE) build -j $(JOBS) ./bench/watch/latency.exe
	$(RUN) ./_build/default/bench/watch/latency.exe _build/default/bin/main.exe

# lancer-mpi's scaling model: measured here, checked against runs here, predicted for
# 16 to 1024 ranks (a still and a 48-frame animation; bench/mpi/bench.sh).
bench-mpi: build
	$(RUN) bash bench/mpi/bench.sh

# What the 16-core run needs on a machine without OCaml, in out/cluster/ and
# out/cluster.tar.gz: the static lancer, lancer-mpi (it needs Open MPI 5's libraries:
# Debian 13's openmpi-bin), lancer-mpirun (only the C library), run16.sh and bounce.rts.
# There: ./run16.sh
cluster-bundle: build static
	rm -rf out/cluster && mkdir -p out/cluster
	install -m 0755 _build/default/bin/static/lancer_static.exe out/cluster/lancer
	install -m 0755 _build/default/bin/mpi/lancer_mpi_main.exe out/cluster/lancer-mpi
	install -m 0755 _build/default/bin/mpi/lancer_mpirun.exe out/cluster/lancer-mpirun
	install -m 0755 bench/mpi/run16.sh out/cluster/run16.sh
	install -m 0644 scenes/bounce.rts out/cluster/bounce.rts
	tar -C out -czf out/cluster.tar.gz cluster
	@echo "out/cluster.tar.gz: unpack it on the 16-core machine and run cluster/run16.sh"

# Random and mutated scenes (parser and evaluator), OBJ files and images for FUZZ_SECONDS
# (default 60); reports the cases tried and the failures, keeps failing inputs in
# fuzz-failures/ and exits 1 if there are any. FUZZ_SEED=K FUZZ_SECONDS=0 replays case K.
# (`LANCER_FUZZ_COUNT=N dune test test/dsl` runs the language's own properties N times.)
FUZZ_SECONDS ?= 60
FUZZ_SEED ?= 1
fuzz: build
	$(RUN) $(DUNE) build -j $(JOBS) ./test/robust/fuzz.exe
	$(RUN) env FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_SEED=$(FUZZ_SEED) ./_build/default/test/robust/fuzz.exe

doc:
	@bash .ci/toolchain setup --doc
	$(RUN) $(DUNE) build @doc
	@echo "The API documentation is in _build/default/_doc/_html/index.html"

# Formats the tree with ocamlformat (the version pinned in .ocamlformat; installed if missing).
fmt:
	bash .ci/toolchain install ocamlformat
	$(RUN) $(DUNE) fmt

clean:
	$(RUN) $(DUNE) clean
	rm -rf out

# Removes the project-local toolchain root (Debian 12 hosts), about 2.5 GB.
clean-toolchain:
	bash .ci/toolchain clean

# Every speed target side by side (bench/embree/bench.sh): lancer against Embree (an own
# harness, bench/embree/) on the scenes of the speed table, an animation against one still,
# the scene language against CPython, a generated scene read beside POV-Ray reading it;
# installs libembree-dev, GNU time, python3 and povray where missing, and skips a row with
# a message where its tool cannot be had.
bench-limit: build
	-@bash .ci/toolchain install libembree-dev time || echo "bench-limit: could not install libembree-dev"
	-@bash .ci/toolchain install python3-minimal || echo "bench-limit: could not install python3"
	-@bash .ci/toolchain install povray || echo "bench-limit: could not install povray"
	$(RUN) bash bench/embree/bench.sh

# lancer against POV-Ray on the scene pairs of scenes/bench/ (installs povray if missing).
bench-povray: build
	bash .ci/toolchain install povray
	$(RUN) bash bench/povray/bench.sh
