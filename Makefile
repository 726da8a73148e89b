# lancer — the two commands a newcomer needs are `make demo` and `make test`;
# each installs what is missing first (see .ci/deps).

DUNE ?= dune
JOBS ?= 2

.PHONY: all deps build demo test golden-update bench bench-povray bench-mpi fuzz doc clean fmt

all: build

deps:
	@bash .ci/deps

build: deps
	$(DUNE) build -j $(JOBS) @install

demo: build
	@mkdir -p out
	$(DUNE) exec --no-build -- lancer render scenes/showcase.rts -o out/showcase.png
	$(DUNE) exec --no-build -- lancer animate scenes/bounce.rts -o out/bounce --width 320 --height 180
	@echo "The showcase is in out/showcase.png; the frames of a bouncing ball are in out/bounce/"
	@command -v ffmpeg >/dev/null 2>&1 && $(DUNE) exec --no-build -- lancer animate scenes/bounce.rts -o out/bounce --width 320 --height 180 --resume --video out/bounce.gif -q && echo "and as a GIF in out/bounce.gif" || true

test: deps
	$(DUNE) build -j $(JOBS) @install
	$(DUNE) test -j $(JOBS) --force

# Re-render every golden image from its scene. Only this command changes goldens.
golden-update: build
	LANCER_UPDATE_GOLDEN=1 $(DUNE) test -j $(JOBS) --force test/golden

bench: build
	$(DUNE) exec --no-build -- lancer bench scaling --counts 1000,10000,100000,1000000
	$(DUNE) exec --no-build -- lancer bench domains --width 1920 --height 1080 --counts 1,2
	$(DUNE) exec --no-build -- lancer bench physics

# lancer-mpi against lancer on this machine: a still and a 48-frame animation.
bench-mpi: build
	bash test/mpi/bench.sh

# Random and mutated scenes (parser and evaluator), OBJ files and images for FUZZ_SECONDS
# (default 60); reports the cases tried and the failures, keeps failing inputs in
# fuzz-failures/ and exits 1 if there are any. FUZZ_SEED=K FUZZ_SECONDS=0 replays case K.
# (`LANCER_FUZZ_COUNT=N dune test test/dsl` runs the language's own properties N times.)
FUZZ_SECONDS ?= 60
FUZZ_SEED ?= 1
fuzz: build
	$(DUNE) build -j $(JOBS) ./test/robust/fuzz.exe
	FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_SEED=$(FUZZ_SEED) ./_build/default/test/robust/fuzz.exe

doc:
	@bash .ci/deps --doc
	$(DUNE) build @doc
	@echo "The API documentation is in _build/default/_doc/_html/index.html"

fmt:
	$(DUNE) fmt

clean:
	$(DUNE) clean
	rm -rf out

# lancer against POV-Ray on the scene pairs of scenes/bench/ (installs povray if missing).
bench-povray: build
	bash test/povray/bench.sh
