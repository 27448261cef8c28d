# kmorph - build, test, run. `make run` and `make test` do all set-up on a
# fresh Debian 12 machine (system packages are installed with apt-get when
# missing).

CC      ?= gcc
BUILD   ?= build
SAN     ?=
OPT     ?= -O3
CSTD    := -std=c11
WARN    := -Wall -Wextra -Werror -Wshadow -Wpointer-arith -Wstrict-prototypes
CFLAGS_BASE := $(CSTD) $(OPT) -g $(WARN) -D_POSIX_C_SOURCE=200809L -fno-common
ifeq ($(SAN),address)
  SANFLAGS := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
endif
ifeq ($(SAN),thread)
  SANFLAGS := -fsanitize=thread -fno-omit-frame-pointer
endif
CFLAGS  := $(CFLAGS_BASE) $(SANFLAGS) $(EXTRA_CFLAGS)
LDFLAGS := $(SANFLAGS) $(EXTRA_LDFLAGS)

# System packages the build and the tests need (Debian 12 names).
PACKAGES := gcc make pkg-config libcmocka-dev libcjson-dev libmicrohttpd-dev \
            clang clang-format libclang-rt-14-dev curl jq valgrind libxml2-utils \
            librsvg2-bin nodejs npm wrk python3 python3-yaml python3-jsonschema \
            chromium python3-fonttools fonts-dejavu-core fonts-liberation2 \
            python3-venv python3-wheel redis-server redis-tools nginx-light \
            libhiredis-dev zlib1g-dev

# The library headers a build needs, each as header:Debian package; a
# build starts by checking them (check-deps) so that a machine without them
# is told to run `make deps` rather than shown a compiler error.
NEEDED_HEADERS ?= cjson/cJSON.h:libcjson-dev microhttpd.h:libmicrohttpd-dev \
                  cmocka.h:libcmocka-dev zlib.h:zlib1g-dev

CJSON_CFLAGS := -I/usr/include/cjson
CJSON_LIBS   := -lcjson
MHD_LIBS     := -lmicrohttpd
ZLIB_LIBS    := -lz

# The one version of the tree (VERSION): the core's generated km/version.h
# and, as -D flags, the CLI's and the daemon's --version and build_info.
KM_VERSION := $(shell cat VERSION)
KM_VERSION_PARTS := $(subst ., ,$(KM_VERSION))
GEN_INC := $(BUILD)/gen/include
VERSION_H := $(GEN_INC)/km/version.h
VERSION_DEF := -DKMORPH_VERSION='"$(KM_VERSION)"'

# Layers: each is a static library; a wrong-way include does not compile
# because the include path of a layer names only the layers below it.
CORE_INC := -Icore/include -I$(GEN_INC)
API_INC  := -Iapi/include $(CORE_INC) $(CJSON_CFLAGS)
SRV_INC  := -Iapi/include

CORE_SRC := $(wildcard core/src/*.c)
API_SRC  := $(wildcard api/src/*.c)
SRV_SRC  := $(wildcard server/src/*.c)
CORE_OBJ := $(CORE_SRC:%.c=$(BUILD)/%.o)
API_OBJ  := $(API_SRC:%.c=$(BUILD)/%.o)
SRV_OBJ  := $(SRV_SRC:%.c=$(BUILD)/%.o)

LIBCORE := $(BUILD)/libkmorph.a
# The shared core: ABI version MAJOR of VERSION in its SONAME, every
# object position-independent and only the KM_API functions exported
# (km/export.h); the static library is built from the same objects.
SO_MAJOR := $(word 1,$(KM_VERSION_PARTS))
SONAME   := libkmorph.so.$(SO_MAJOR)
LIBSO    := $(BUILD)/libkmorph.so.$(KM_VERSION)
CORE_PIC := -fPIC -fvisibility=hidden -fno-semantic-interposition
# -z defs: the library names every library it needs (libm); sanitizer
# builds leave their runtime's symbols to the executable.
SO_DEFS  := $(if $(SANFLAGS),,-Wl,-z,defs)
LIBAPI  := $(BUILD)/libkmapi.a
CLI     := $(BUILD)/kmorph
DAEMON  := $(BUILD)/kmorphd

UNIT_SRC  := $(wildcard tests/core/test_*.c)
APIT_SRC  := $(wildcard tests/api/test_*.c)
UNIT_BIN  := $(UNIT_SRC:%.c=$(BUILD)/%)
APIT_BIN  := $(APIT_SRC:%.c=$(BUILD)/%)
SUPPORT_SRC := $(wildcard tests/support/*.c)

.PHONY: all deps check-deps check build run test test-compound test-unit test-asan test-server test-clients check-layers format-check \
        bench bench-http fuzz fuzz-svg clean format examples \
        test-fuzz test-hardening bench-load bench-hostile install uninstall \
        test-packaging image

all: build

deps:
	@missing=""; for p in $(PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || \
	  [ "$$p" = npm -a -n "$$(command -v npm)" ] || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

build: $(LIBCORE) $(LIBSO) $(LIBAPI) $(CLI) $(if $(SRV_SRC),$(DAEMON))

# Each header is preprocessed alone, so the compiler's own search path
# decides, as it will for the real sources.
check-deps:
	@missing=""; for hp in $(NEEDED_HEADERS); do \
	  h=$${hp%%:*}; \
	  echo "#include <$$h>" | $(CC) -E -x c - >/dev/null 2>&1 || \
	    missing="$$missing $$h ($${hp#*:})"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "kmorph: missing headers:$$missing"; \
	  echo "kmorph: run \`make deps\` to install the system packages (apt-get), then make again"; \
	  exit 1; \
	fi

# The loop to run between edits: the libraries, the CLI and the daemon, the
# layer check, then every unit and api test (gcc -O3), counted in
# $(BUILD)/check-results.txt. KM_TEST=NAME runs only the tests NAME selects.
check:
	@$(MAKE) --no-print-directory build check-layers
	@rm -f $(BUILD)/check-results.txt
	@KM_RESULTS=$(BUILD)/check-results.txt $(MAKE) --no-print-directory test-unit
	@awk '{p += $$2; f += $$3} END {printf "check: %d tests passed, %d failed\n", p, f}' \
	  $(BUILD)/check-results.txt

$(VERSION_H): packaging/version.h.in VERSION
	@mkdir -p $(@D)
	sed -e 's/@VERSION@/$(KM_VERSION)/' -e 's/@MAJOR@/$(word 1,$(KM_VERSION_PARTS))/' \
	  -e 's/@MINOR@/$(word 2,$(KM_VERSION_PARTS))/' -e 's/@PATCH@/$(word 3,$(KM_VERSION_PARTS))/' $< > $@

$(BUILD)/core/%.o: core/%.c | check-deps $(VERSION_H)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CORE_PIC) $(CORE_INC) -MMD -MP -c $< -o $@

$(BUILD)/api/%.o: api/%.c | check-deps $(VERSION_H)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(API_INC) -MMD -MP -c $< -o $@

$(BUILD)/server/%.o: server/%.c | check-deps
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(SRV_INC) $(VERSION_DEF) -MMD -MP -c $< -o $@

$(LIBCORE): $(CORE_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

$(LIBSO): $(CORE_OBJ)
	@mkdir -p $(@D)
	$(CC) -shared -Wl,-soname,$(SONAME) $(SO_DEFS) -o $@ $^ -lm $(LDFLAGS)
	ln -sf $(@F) $(@D)/$(SONAME)
	ln -sf $(SONAME) $(@D)/libkmorph.so

$(LIBAPI): $(API_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

$(CLI): cli/kmorph.c $(LIBAPI) $(LIBCORE) VERSION | check-deps
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(SRV_INC) $(VERSION_DEF) $< -o $@ $(LIBAPI) $(LIBCORE) $(CJSON_LIBS) -lm -lpthread $(LDFLAGS)

$(BUILD)/server/src/config.o $(BUILD)/server/src/metrics.o: VERSION

$(DAEMON): $(SRV_OBJ) $(LIBAPI) $(LIBCORE)
	@mkdir -p $(@D)
	$(CC) $(SRV_OBJ) -o $@ $(LIBAPI) $(LIBCORE) $(MHD_LIBS) $(ZLIB_LIBS) $(CJSON_LIBS) -lhiredis -lm -lpthread $(LDFLAGS)

$(BUILD)/tests/core/%: tests/core/%.c $(SUPPORT_SRC) $(LIBCORE) | check-deps
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CORE_INC) -Itests/support $(CJSON_CFLAGS) $< $(SUPPORT_SRC) -o $@ $(LIBCORE) -lcmocka $(CJSON_LIBS) -lm $(LDFLAGS)

$(BUILD)/tests/api/%: tests/api/%.c $(SUPPORT_SRC) $(LIBAPI) $(LIBCORE) | check-deps
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(API_INC) -Itests/support $< $(SUPPORT_SRC) -o $@ $(LIBAPI) $(LIBCORE) -lcmocka $(CJSON_LIBS) -lm $(LDFLAGS)

# The out-of-memory tests (tests/core/test_oom.c, tests/api/test_api_oom.c)
# define the allocation hook themselves, so they link libraries built with
# KM_ALLOC_HOOKED, where it is called out of line (km/alloc.h); the normal
# build inlines it to libc.
HOOK_CORE_OBJ := $(CORE_SRC:%.c=$(BUILD)/hooked/%.o)
HOOK_API_OBJ  := $(API_SRC:%.c=$(BUILD)/hooked/%.o)
HOOK_LIBCORE  := $(BUILD)/hooked/libkmorph.a
HOOK_LIBAPI   := $(BUILD)/hooked/libkmapi.a

$(BUILD)/hooked/core/%.o: core/%.c | check-deps $(VERSION_H)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -DKM_ALLOC_HOOKED $(CORE_INC) -MMD -MP -c $< -o $@

$(BUILD)/hooked/api/%.o: api/%.c | check-deps $(VERSION_H)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -DKM_ALLOC_HOOKED $(API_INC) -MMD -MP -c $< -o $@

$(HOOK_LIBCORE): $(HOOK_CORE_OBJ)
	rm -f $@ && ar rcs $@ $^

$(HOOK_LIBAPI): $(HOOK_API_OBJ)
	rm -f $@ && ar rcs $@ $^

$(BUILD)/tests/core/test_oom: tests/core/test_oom.c $(SUPPORT_SRC) $(HOOK_LIBCORE) | check-deps
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -DKM_ALLOC_HOOKED $(CORE_INC) -Itests/support $(CJSON_CFLAGS) $< $(SUPPORT_SRC) -o $@ $(HOOK_LIBCORE) -lcmocka $(CJSON_LIBS) -lm $(LDFLAGS)

$(BUILD)/tests/api/test_api_oom: tests/api/test_api_oom.c $(SUPPORT_SRC) $(HOOK_LIBAPI) $(HOOK_LIBCORE) | check-deps
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -DKM_ALLOC_HOOKED $(API_INC) -Itests/support $< $(SUPPORT_SRC) -o $@ $(HOOK_LIBAPI) $(HOOK_LIBCORE) -lcmocka $(CJSON_LIBS) -lm $(LDFLAGS)

-include $(CORE_OBJ:.o=.d) $(API_OBJ:.o=.d) $(SRV_OBJ:.o=.d)
-include $(HOOK_CORE_OBJ:.o=.d) $(HOOK_API_OBJ:.o=.d)

# core/ must build with libm alone and must not include anything above it.
check-layers:
	@if grep -rnE '#include *[<"](kmapi|cJSON|microhttpd|stdio|pthread)' core/; then \
	  echo "core/ includes something above it or does I/O"; exit 1; fi
	@if grep -rnE '#include *[<"](km/|microhttpd)' api/ | grep -v '^api/src'; then \
	  echo "api headers leak core or transport"; exit 1; fi
	@if grep -rnE '#include *[<"](km/|cJSON)' server/; then \
	  echo "server/ reaches past the api layer"; exit 1; fi
	@if grep -nE '(^|[^A-Za-z0-9_])(malloc|calloc|realloc|free|strdup|strndup)\(' \
	    $(filter-out core/src/alloc.c,$(CORE_SRC)) $(API_SRC) core/src/*.h api/src/*.h | \
	    grep -vE '^[^:]*:[0-9]+: *(/\*|\*)'; then \
	  echo "core/ and api/ allocate through km/alloc.h only"; exit 1; fi
	@echo "layers: ok"

test-unit: $(UNIT_BIN) $(APIT_BIN) $(CLI)
	@KMORPH_CLI=$(CLI) tests/run-tests.sh $(UNIT_BIN) $(APIT_BIN)

test: deps
	@rm -f build/test-results.txt
	@$(MAKE) --no-print-directory build check-layers
	@tests/checks.sh || true
	@$(MAKE) --no-print-directory CC=clang BUILD=build/clang build >/dev/null
	@echo "== unit and contract-layer tests (gcc -O3)"
	@$(MAKE) --no-print-directory test-unit
	@echo "== the same under AddressSanitizer + UndefinedBehaviorSanitizer"
	@$(MAKE) --no-print-directory BUILD=build/asan SAN=address OPT=-O1 test-unit
	@echo "== kmorphd over HTTP: contract, jobs, load, shutdown"
	@$(MAKE) --no-print-directory test-server || true
	@echo "== clients: curl, JS, Python and the web page in Chromium"
	@$(MAKE) --no-print-directory test-clients || true
	@echo "== scale-out: redis-server, two kmorphd and nginx on loopback (tests/cluster)"
	@$(MAKE) --no-print-directory test-cluster || true
	@echo "== fuzzing: the request and SVG fuzz targets for $(TEST_FUZZ_SECONDS) s each (ASan, UBSan, LSan)"
	@$(MAKE) --no-print-directory test-fuzz || true
	@echo "== hardening: bad-input barrage, daemon under ASan, leaks, load, faults"
	@$(MAKE) --no-print-directory test-hardening || true
	@echo "== packaging: make install into a temporary DESTDIR, used from there"
	@$(MAKE) --no-print-directory test-packaging || true
	@tests/summarise.sh

# Compound morphs of every fixture pair at all 41 frames (make test: 21),
# with the per-pair figures in build/compound-morphs.txt.
test-compound: build
	@cd tests/fixtures/compound && KMORPH=$(CURDIR)/$(CLI) \
	  KM_COMPOUND_REPORT=$(CURDIR)/build/compound-morphs.txt \
	  /usr/bin/python3 -m unittest -v test_compound_morphs

# The daemon over real HTTP (loopback, ephemeral ports); appends its counts
# to build/test-results.txt like the other suites.
test-server: build
	@tests/server/run.sh

# The clients (clients/) against live daemons on ephemeral loopback ports,
# and the web page in headless Chromium; appends its counts like the others.
test-clients: build
	@tests/clients/run.sh

# Several kmorphd sharing jobs through a real redis-server, behind a real
# nginx, on loopback ports (tests/cluster); and the checks of deploy/.
# Appends its counts like the others.
.PHONY: test-cluster run-cluster stop-cluster bench-cluster
test-cluster: build
	@tests/cluster/run.sh

# redis-server, two kmorphd and nginx in the background on loopback (pid
# files and logs in build/cluster/), for trying by hand; stop-cluster ends
# them by pid. Ports: CLUSTER_PORT, CLUSTER_KMORPHD_PORTS, CLUSTER_REDIS_PORT.
run-cluster: deps build
	@tools/run_cluster.py start

stop-cluster:
	@tools/run_cluster.py stop

# Throughput of 200 jobs on one instance against two, and the Redis job
# store against the in-memory one (bench/cluster/bench_cluster.py).
bench-cluster: deps build
	@python3 bench/cluster/bench_cluster.py

# Throughput and latency of kmorphd with wrk (see bench/http/run.sh).
bench-http: deps build
	@bench/http/run.sh

run: deps build
	@if [ -x $(DAEMON) ]; then exec $(DAEMON) --bind 127.0.0.1 --port 8080; \
	else echo "kmorphd not built yet: CLI demo"; \
	  $(CLI) signature < docs/examples/circle-signature.json; fi

bench: deps bench-morph bench-shapes bench-e2e
	@$(MAKE) --no-print-directory build/bench/bench_core build/bench/bench_avoid build/bench/bench_repair
	build/bench/bench_core
	build/bench/bench_avoid
	build/bench/bench_repair

# End to end, as users get it: 1,000-frame morphs of glyph and icon pairs
# (one contour and compound) and the shapes.json pairs through the CLI
# and over HTTP to a live kmorphd, JSON with metrics off and on and SVG,
# per frame beside flubber's default and flubber at equal accuracy, with
# bytes and control points per frame (bench/e2e/run.py; E2E_ARGS passes
# options, e.g. --frames 200 --runs 1).
.PHONY: bench-e2e
bench-e2e: deps build
	@if [ -d bench/flubber/node_modules/flubber ] || \
	   (cd bench/flubber && npm ci --no-audit --no-fund >/dev/null 2>&1); then \
	  python3 bench/e2e/run.py $(E2E_ARGS); \
	else echo "flubber could not be installed with npm: kmorph figures only"; \
	  python3 bench/e2e/run.py --no-flubber $(E2E_ARGS); fi

# 60-frame morphs (bench/bench_morph.c), and the shapes.json pairs beside
# flubber from npm (bench/flubber, a benchmark-only dependency; skipped
# without npm).
.PHONY: bench-morph
bench-morph: deps
	@$(MAKE) --no-print-directory build/bench/bench_morph
	@rm -f build/bench/flubber.txt; \
	if [ -d bench/flubber/node_modules/flubber ] || \
	   (cd bench/flubber && npm ci --no-audit --no-fund >/dev/null 2>&1); then \
	  (cd bench/flubber && node bench_flubber.js ../../tests/fixtures/shapes.json) \
	    > build/bench/flubber.txt || rm -f build/bench/flubber.txt; \
	else echo "flubber could not be installed with npm: kmorph figures only"; fi
	build/bench/bench_morph build/bench/flubber.txt

# 60-frame morphs of compound shapes (bench/shape_pairs.json: glyphs with
# holes, 4-contour icons), the CLI end to end and the core in-process,
# beside flubber's interpolateAll / combine / separate on the same pairs.
.PHONY: bench-shapes
bench-shapes: deps build
	@$(MAKE) --no-print-directory build/bench/bench_shapes
	@rm -f build/bench/flubber-shapes.txt; \
	if [ -d bench/flubber/node_modules/flubber ] || \
	   (cd bench/flubber && npm ci --no-audit --no-fund >/dev/null 2>&1); then \
	  (cd bench/flubber && node bench_flubber_shapes.js ../shape_pairs.json \
	    ../../tests/fixtures/compound) > build/bench/flubber-shapes.txt || \
	    rm -f build/bench/flubber-shapes.txt; \
	else echo "flubber could not be installed with npm: kmorph figures only"; fi
	build/bench/bench_shapes bench/shape_pairs.json $(CLI) build/bench/flubber-shapes.txt

build/bench/bench_shapes: bench/bench_shapes.c $(LIBAPI) $(LIBCORE)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(API_INC) -Iapi/src $< -o $@ $(LIBAPI) $(LIBCORE) $(CJSON_LIBS) -lm $(LDFLAGS)

build/bench/bench_morph: bench/bench_morph.c $(LIBCORE)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CORE_INC) $(CJSON_CFLAGS) $< -o $@ $(LIBCORE) $(CJSON_LIBS) -lm $(LDFLAGS)

build/bench/bench_avoid: bench/bench_avoid.c bench/bench_glyphs.h $(LIBCORE)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CORE_INC) $(CJSON_CFLAGS) $< -o $@ $(LIBCORE) $(CJSON_LIBS) -lm $(LDFLAGS)

build/bench/bench_repair: bench/bench_repair.c bench/bench_glyphs.h $(LIBCORE)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CORE_INC) $(CJSON_CFLAGS) $< -o $@ $(LIBCORE) $(CJSON_LIBS) -lm $(LDFLAGS)

build/bench/%: bench/%.c $(LIBCORE)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(CORE_INC) $< -o $@ $(LIBCORE) -lm $(LDFLAGS)

# The paper's spiral pair (kappa = s and kappa = -s/2 on [0, 4]) as
# filmstrips and curvature plots for both methods, written to docs/.
EXAMPLE_SVGS := $(patsubst docs/examples/%.json,docs/%.svg,$(wildcard docs/examples/spirals-*-*.json))
examples: $(CLI) $(EXAMPLE_SVGS)
docs/%.svg: docs/examples/%.json $(CLI)
	$(CLI) morph < $< > $@

# Every C file of the tree in the layout of .clang-format (the generated
# contract api/src/openapi.c aside); make test checks it (tests/checks.sh).
FORMAT_FILES = $(filter-out api/src/openapi.c,$(shell git ls-files '*.c' '*.h' 2>/dev/null))
format:
	clang-format -i $(FORMAT_FILES)

format-check:
	@clang-format --dry-run --Werror $(FORMAT_FILES) && echo "format: ok"

# libFuzzer on the SVG path parser and writer for FUZZ_SECONDS (default 60);
# new inputs go to build/fuzz/svg_path-corpus, seeds stay in tests/fuzz.
FUZZ_SECONDS ?= 60
fuzz-svg: deps
	@mkdir -p build/fuzz/svg_path-corpus
	clang $(CSTD) -g -O1 -D_POSIX_C_SOURCE=200809L \
	  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
	  -Iapi/src $(CORE_INC) tests/fuzz/svg_path/fuzz_svg_path.c \
	  api/src/svg_parse.c api/src/svg_write.c $(CORE_SRC) -lm \
	  -o build/fuzz/fuzz_svg_path
	build/fuzz/fuzz_svg_path -max_total_time=$(FUZZ_SECONDS) -timeout=10 \
	  -dict=tests/fuzz/svg_path/svg_path.dict \
	  build/fuzz/svg_path-corpus tests/fuzz/svg_path/corpus

# Every libFuzzer target tests/fuzz/<name>/fuzz_<name>.c, linked with the
# whole api and core layers. `make fuzz` runs each for FUZZ_SECONDS (600
# unless given), `make test-fuzz` for TEST_FUZZ_SECONDS; both record counts
# like the other suites (tests/hardening/fuzz.sh).
FUZZ_NAMES := $(patsubst tests/fuzz/%/,%,$(dir $(wildcard tests/fuzz/*/fuzz_*.c)))
FUZZ_BINS  := $(FUZZ_NAMES:%=build/fuzz/fuzz_%)
TEST_FUZZ_SECONDS ?= 60
# make test fuzzes every target, the structured `curves` one included (its
# inputs found so far are regression seeds in tests/fuzz/curves/corpus).
TEST_FUZZ_NAMES := $(FUZZ_NAMES)
FUZZ_CFLAGS := $(CSTD) -g -O1 $(WARN) -D_POSIX_C_SOURCE=200809L \
  -fsanitize-coverage-ignorelist=tests/fuzz/coverage-ignore.txt \
  -fsanitize=address,undefined -fno-sanitize-recover=undefined \
  -Iapi/include -Iapi/src $(CORE_INC) $(CJSON_CFLAGS)
FUZZ_OBJ := $(CORE_SRC:%.c=build/fuzz/obj/%.o) $(API_SRC:%.c=build/fuzz/obj/%.o)
# The core's comparisons are not traced: they are loop counters of numeric
# loops, which gave libFuzzer nothing to steer toward and were 40% of the
# time of the curves target's slowest inputs (the api layer's, against
# field names and limits, are).
build/fuzz/obj/core/%.o: FUZZ_TRACE := -fno-sanitize-coverage=trace-cmp
build/fuzz/obj/%.o: %.c tests/fuzz/coverage-ignore.txt | $(VERSION_H)
	@mkdir -p $(@D)
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link $(FUZZ_TRACE) -MMD -MP -c $< -o $@
-include $(FUZZ_OBJ:.o=.d)
define FUZZ_RULE
build/fuzz/fuzz_$(1): tests/fuzz/$(1)/fuzz_$(1).c $(wildcard tests/fuzz/*.h) $(FUZZ_OBJ)
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer $$< $(FUZZ_OBJ) $(CJSON_LIBS) -lm -o $$@
endef
$(foreach t,$(FUZZ_NAMES),$(eval $(call FUZZ_RULE,$(t))))

fuzz: deps $(FUZZ_BINS)
	@tests/hardening/fuzz.sh $(if $(filter file undefined,$(origin FUZZ_SECONDS)),600,$(FUZZ_SECONDS)) $(FUZZ_NAMES)

test-fuzz: $(FUZZ_BINS)
	@FUZZ_SEED=1 tests/hardening/fuzz.sh $(TEST_FUZZ_SECONDS) $(TEST_FUZZ_NAMES)

# Bad-input barrage, the daemon under ASan, leak checks of the CLI, load
# and faults (tests/hardening/run.sh; HARDENING_LONG=1 for the long run).
test-hardening: build
	@$(MAKE) --no-print-directory BUILD=build/asan SAN=address OPT=-O1 build >/dev/null
	@tests/hardening/run.sh

bench-load: build
	@HARDENING_LONG=1 tests/hardening/run.sh load faults

# Peak RSS and time of kmorphd under hostile clients (bench/hostile.py).
bench-hostile: build
	@python3 bench/hostile.py --daemon $(DAEMON)

# ------------------------------------------------------------ install
# make install [PREFIX=/usr/local] [DESTDIR=staging]: the shared and
# static core, its km/ headers and kmorph.pc, the CLI and the daemon, the
# web page (the installed daemon's default web root, found beside its
# executable), the man pages, the systemd unit and its environment file.
# The configured paths are written into kmorph.pc, the unit and the man
# page; DESTDIR is only where the files go. make uninstall removes them.
PREFIX     ?= /usr/local
BINDIR     ?= $(PREFIX)/bin
SBINDIR    ?= $(PREFIX)/sbin
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
DATADIR    ?= $(PREFIX)/share
MANDIR     ?= $(DATADIR)/man
UNITDIR    ?= $(PREFIX)/lib/systemd/system
SYSCONFDIR ?= /etc
INSTALL    ?= install

# alloc.h is left out: its hook is a seam of the test build only.
KM_HEADERS := $(filter-out core/include/km/alloc.h,$(wildcard core/include/km/*.h))
WEB_FILES  := $(wildcard clients/web/*)
PKG_GEN    := $(BUILD)/packaging
PKG_SUBST  := sed -e 's|@VERSION@|$(KM_VERSION)|g' -e 's|@PREFIX@|$(PREFIX)|g' \
  -e 's|@LIBDIR@|$(LIBDIR)|g' -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|g' \
  -e 's|@SBINDIR@|$(SBINDIR)|g' -e 's|@DATADIR@|$(DATADIR)|g' \
  -e 's|@SYSCONFDIR@|$(SYSCONFDIR)|g'
PKG_FILES  := $(PKG_GEN)/kmorph.pc $(PKG_GEN)/kmorph.1 $(PKG_GEN)/kmorphd.8 \
              $(PKG_GEN)/kmorphd.service $(PKG_GEN)/kmorphd.env

# The paths are baked in: a different PREFIX rewrites them.
$(PKG_GEN)/paths: FORCE
	@mkdir -p $(@D)
	@echo '$(KM_VERSION) $(PREFIX) $(LIBDIR) $(INCLUDEDIR) $(SBINDIR) $(DATADIR) $(SYSCONFDIR)' > $@.new
	@cmp -s $@.new $@ && rm -f $@.new || mv $@.new $@
.PHONY: FORCE
FORCE:

$(PKG_GEN)/%: packaging/%.in $(PKG_GEN)/paths
	$(PKG_SUBST) $< > $@
$(PKG_GEN)/kmorph.1 $(PKG_GEN)/kmorphd.env: $(PKG_GEN)/%: packaging/% $(PKG_GEN)/paths
	$(PKG_SUBST) $< > $@
$(PKG_GEN)/kmorphd.8: packaging/kmorphd.8.in packaging/man-options.awk $(DAEMON) $(PKG_GEN)/paths
	$(DAEMON) --help | awk -v web_root_default='$(DATADIR)/kmorph/web when installed, else clients/web' \
	  -f packaging/man-options.awk > $@.options
	$(PKG_SUBST) $< | sed -e '/^@OPTIONS@$$/{r $@.options' -e 'd}' > $@
	rm -f $@.options

install: build $(PKG_FILES)
	$(INSTALL) -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(SBINDIR) $(DESTDIR)$(LIBDIR)/pkgconfig \
	  $(DESTDIR)$(INCLUDEDIR)/km $(DESTDIR)$(DATADIR)/kmorph/web \
	  $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(MANDIR)/man8 $(DESTDIR)$(UNITDIR)
	$(INSTALL) -m 755 $(CLI) $(DESTDIR)$(BINDIR)/kmorph
	$(INSTALL) -m 755 $(DAEMON) $(DESTDIR)$(SBINDIR)/kmorphd
	$(INSTALL) -m 755 $(LIBSO) $(DESTDIR)$(LIBDIR)/
	ln -sf $(notdir $(LIBSO)) $(DESTDIR)$(LIBDIR)/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(LIBDIR)/libkmorph.so
	$(INSTALL) -m 644 $(LIBCORE) $(DESTDIR)$(LIBDIR)/libkmorph.a
	$(INSTALL) -m 644 $(KM_HEADERS) $(VERSION_H) $(DESTDIR)$(INCLUDEDIR)/km/
	$(INSTALL) -m 644 $(PKG_GEN)/kmorph.pc $(DESTDIR)$(LIBDIR)/pkgconfig/
	$(INSTALL) -m 644 $(WEB_FILES) $(DESTDIR)$(DATADIR)/kmorph/web/
	$(INSTALL) -m 644 $(PKG_GEN)/kmorphd.env $(DESTDIR)$(DATADIR)/kmorph/
	$(INSTALL) -m 644 $(PKG_GEN)/kmorph.1 $(DESTDIR)$(MANDIR)/man1/
	$(INSTALL) -m 644 $(PKG_GEN)/kmorphd.8 $(DESTDIR)$(MANDIR)/man8/
	$(INSTALL) -m 644 $(PKG_GEN)/kmorphd.service $(DESTDIR)$(UNITDIR)/

# Only what install wrote: the folders are left when something else put
# files there, and a site's @SYSCONFDIR@/kmorph/kmorphd.env is its own.
uninstall:
	rm -f $(DESTDIR)$(BINDIR)/kmorph $(DESTDIR)$(SBINDIR)/kmorphd \
	  $(DESTDIR)$(LIBDIR)/$(notdir $(LIBSO)) $(DESTDIR)$(LIBDIR)/$(SONAME) \
	  $(DESTDIR)$(LIBDIR)/libkmorph.so $(DESTDIR)$(LIBDIR)/libkmorph.a \
	  $(DESTDIR)$(LIBDIR)/pkgconfig/kmorph.pc \
	  $(addprefix $(DESTDIR)$(INCLUDEDIR)/km/,$(notdir $(KM_HEADERS) $(VERSION_H))) \
	  $(addprefix $(DESTDIR)$(DATADIR)/kmorph/web/,$(notdir $(WEB_FILES))) \
	  $(DESTDIR)$(DATADIR)/kmorph/kmorphd.env \
	  $(DESTDIR)$(MANDIR)/man1/kmorph.1 $(DESTDIR)$(MANDIR)/man8/kmorphd.8 \
	  $(DESTDIR)$(UNITDIR)/kmorphd.service
	-rmdir $(DESTDIR)$(INCLUDEDIR)/km $(DESTDIR)$(DATADIR)/kmorph/web \
	  $(DESTDIR)$(DATADIR)/kmorph 2>/dev/null

# The container image from the Dockerfile, labelled with VERSION: podman,
# else docker (neither is needed by the build or the tests). podman
# builds the docker format: the OCI one has no HEALTHCHECK.
ENGINE ?= $(firstword $(shell command -v podman docker 2>/dev/null))
image:
	@[ -n "$(ENGINE)" ] || { echo "no podman or docker: install one, or set ENGINE"; exit 1; }
	$(ENGINE) build $(if $(findstring podman,$(ENGINE)),--format docker) \
	  --build-arg KMORPH_VERSION=$(KM_VERSION) -t kmorph:$(KM_VERSION) .

# make install into a temporary DESTDIR, then the installed library built
# against with pkg-config, the installed daemon serving the installed
# page, the man pages and the unit checked (tests/packaging/run.sh).
test-packaging: build
	@tests/packaging/run.sh

clean:
	rm -rf build
