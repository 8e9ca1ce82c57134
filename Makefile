# cdsp: top-level Makefile. `make` builds everything buildable here,
# `make check` runs every test, `make bench` prints the figures,
# `make demo` runs the daemon on its simulated camera.
#
# Layout: lib/ + include/ -> libcdsp.a (dependency-free C99);
# host/ -> libcdsp_host.a (files, calibration, records, the wire protocol);
# tools/, daemon/ -> the programs, which use host/ and never each other;
# tests/ -> everything that checks them.
# Components add their own rules in */*.mk fragments (included below) and
# register their steps in CHECK_STEPS / BENCH_STEPS / ALL_TARGETS.

CC      ?= cc
CLANG   ?= clang
AR      ?= ar
BUILD   ?= build

WARN    := -Wall -Wextra -pedantic -Werror -Wmissing-prototypes \
           -Wstrict-prototypes -Wshadow -Wvla -Wpointer-arith
CSTD    := -std=c99
OPT     ?= -O3
BASE_CFLAGS := $(CSTD) $(WARN) -fno-math-errno -Iinclude -MMD -MP
SAN_FLAGS   := -fsanitize=address,undefined -fno-sanitize-recover=all \
               -fno-omit-frame-pointer -g

LIB_SRC  := $(sort $(wildcard lib/*.c))
LIB_TEST := $(sort $(wildcard tests/lib/test_*.c))

ALL_TARGETS :=
CHECK_STEPS :=
BENCH_STEPS :=

.DEFAULT_GOAL := all
.PHONY: all check check-steps check-run bench bench-steps demo deps clean size-m4f

# ---------------------------------------------------------------------------
# libcdsp in several variants: one template, one build directory each.
#   $(1) variant name, $(2) compiler, $(3) flags variable name
# ---------------------------------------------------------------------------
define lib_variant
$(1)_DIR   := $(BUILD)/$(1)
$(1)_OBJ   := $$(patsubst lib/%.c,$$($(1)_DIR)/lib/%.o,$$(LIB_SRC))
$(1)_LIB   := $$($(1)_DIR)/libcdsp.a
$(1)_TESTS := $$(patsubst tests/lib/%.c,$$($(1)_DIR)/tests/%,$$(LIB_TEST))

$$($(1)_LIB): $$($(1)_OBJ)
	@mkdir -p $$(@D)
	rm -f $$@ && $(AR) rcs $$@ $$^

$$($(1)_DIR)/lib/%.o: lib/%.c
	@mkdir -p $$(@D)
	$(2) $$($(3)) -c $$< -o $$@

$$($(1)_DIR)/tests/support.o: tests/lib/support.c tests/lib/support.h
	@mkdir -p $$(@D)
	$(2) $$($(3)) -Itests/lib -c $$< -o $$@

$$($(1)_DIR)/tests/%: tests/lib/%.c $$($(1)_DIR)/tests/support.o $$($(1)_LIB)
	@mkdir -p $$(@D)
	$(2) $$($(3)) -Itests/lib $$< $$($(1)_DIR)/tests/support.o $$($(1)_LIB) -lcmocka -lm -o $$@

-include $$($(1)_OBJ:.o=.d)
endef

HOST_CFLAGS  := $(BASE_CFLAGS) $(OPT) -g
FLOAT_CFLAGS := $(BASE_CFLAGS) $(OPT) -g -DCDSP_SINGLE -Wdouble-promotion
ASAN_CFLAGS  := $(BASE_CFLAGS) -O1 $(SAN_FLAGS)

$(eval $(call lib_variant,host,$(CC),HOST_CFLAGS))
$(eval $(call lib_variant,float,$(CC),FLOAT_CFLAGS))
$(eval $(call lib_variant,asan,$(CLANG),ASAN_CFLAGS))

# The library users link: build/libcdsp.a (double precision, host).
$(BUILD)/libcdsp.a: $(host_LIB)
	cp $< $@

# build/float/libcdsp.a: the single-precision (CDSP_SINGLE) library the
# README offers for FPUs without double; built by `make` too.
ALL_TARGETS += $(BUILD)/libcdsp.a $(float_LIB)

# Cortex-M4F float build of libcdsp.a, size printed by `make check`.
M4F_CC     ?= arm-none-eabi-gcc
M4F_CFLAGS := $(CSTD) $(WARN) -fno-math-errno -Iinclude -MMD -MP -Os -g \
              -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 \
              -DCDSP_SINGLE -Wdouble-promotion -ffunction-sections -fdata-sections
$(eval $(call lib_variant,m4f,$(M4F_CC),M4F_CFLAGS))

size-m4f: $(m4f_LIB)
	@arm-none-eabi-size -t $(m4f_LIB)

# Every check step records its result through this (before the fragments:
# some expand it when they are read, in $(eval)).
RUN := tests/run.sh $(BUILD)/check-results

# ---------------------------------------------------------------------------
# Component fragments (tools, daemon, MCU, VM harnesses...). The host
# library first: every part after it links it. The daemon's own sub-fragment
# (daemon/sanitize.mk) is included by daemon/daemon.mk; the others read
# nothing another fragment defines, so their order does not matter.
# ---------------------------------------------------------------------------
include host/host.mk
include daemon/daemon.mk
include $(sort $(wildcard tools/*.mk tests/*/*.mk))

# ---------------------------------------------------------------------------
# Checks of the library itself.
# ---------------------------------------------------------------------------

.PHONY: check-lib-host check-lib-float check-lib-asan check-lib-symbols check-lib-m4f
check-lib-host: $(host_TESTS)
	@for t in $^; do $(RUN) "host/$$(basename $$t)" $$t || exit 1; done
check-lib-float: $(float_TESTS)
	@for t in $^; do $(RUN) "float/$$(basename $$t)" $$t || exit 1; done
check-lib-asan: $(asan_TESTS)
	@for t in $^; do ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(RUN) "asan/$$(basename $$t)" $$t || exit 1; done
check-lib-symbols: $(host_LIB) $(m4f_LIB)
	@$(RUN) "lib/no-forbidden-symbols" tests/check_symbols.sh $(host_LIB) $(m4f_LIB)
check-lib-m4f: $(m4f_LIB)
	@$(RUN) "lib/m4f-build-size" arm-none-eabi-size -t $(m4f_LIB)

CHECK_STEPS := check-lib-host check-lib-float check-lib-asan check-lib-symbols \
               check-lib-m4f $(CHECK_STEPS)

# ---------------------------------------------------------------------------
# Packages (tests/deps.sh, lists in .ci/packages.d/): `make demo` and
# `make check` install what they need (root: apt-get; a user: sudo -n;
# otherwise they print the command and exit 2 before compiling anything);
# a plain `make` only checks. Each then runs a fresh make, whose
# $(shell pkg-config ...) sees what was just installed.
# ---------------------------------------------------------------------------
DEPS_BUILD := lib tool daemon calib fakecam

all:
	@tests/deps.sh check $(DEPS_BUILD)
	@$(MAKE) --no-print-directory build-all
build-all: $(ALL_TARGETS)

# `make check`: every step of CHECK_STEPS, CHECK_JOBS at a time, in two
# makes (README "Testing"):
#  1. the steps' prerequisites, all of them, built by one make (-k -j, with
#     RUN=true: the steps' commands are not run), so that each file is
#     built once, by one process, however the steps are then scheduled;
#  2. check-run: the steps themselves, -k -j: every step runs, a failure is
#     counted and the others go on; -Otarget prints each step's output
#     whole (tests/run.sh buffers each suite's output too). Steps that must
#     not overlap are in a lane (CHECK_LANES below): a lane runs its steps
#     one after the other, in a make of its own (-k -j1), beside the other
#     lanes and the free steps. CHECK_FIRST starts the long ones first, so
#     that the short ones fill the other job slot.
# A step's assertions never depend on the machine's speed (STYLE.md), so
# they hold with another step on the other core; one core (taskset -c 0:
# nproc says 1) runs them one at a time, as `make -k check-steps` does.
# If make 1 failed (a build is broken), make 2 runs -j1: a broken build is
# then attempted by one process at a time, its errors shown per step.
CHECK_JOBS ?= $(shell nproc 2>/dev/null || echo 1)
check:
	@tests/deps.sh ensure all
	@mkdir -p $(BUILD) && rm -f $(BUILD)/check-results
	@t0=$$(date +%s); \
	 $(MAKE) --no-print-directory -k -j$(CHECK_JOBS) check-steps RUN=true; b=$$?; t1=$$(date +%s); \
	 $(MAKE) --no-print-directory -k -j$$([ $$b -eq 0 ] && echo $(CHECK_JOBS) || echo 1) -Otarget \
	     check-run; r=$$?; \
	 tests/summary.sh $(BUILD)/check-results $$(( b != 0 || r != 0 )) $$t0 $$t1

# Every step, in registration order (make -k check-steps: one at a time).
check-steps: $(CHECK_STEPS)

# Lanes: steps that cannot run at the same time as each other, each lane
# one list CHECK_LANE_<name> (registered where the steps are); a step in no
# lane is free. gvcp: the fake GigE camera (tests/fakecam) listens on
# GVCP's fixed port 3956 of 127.0.0.1, one camera per machine; the scripts
# wait for /tmp/cdsp-fakecam-gvcp.lock, bounded, and would count a long
# wait as a failure.
CHECK_LANES := gvcp
CHECK_LANED := $(foreach l,$(CHECK_LANES),$(CHECK_LANE_$(l)))
# The long steps and lanes, longest first (per-step seconds of `make
# check`, tests/summary.sh); the other steps follow in registration order.
# (measured, one at a time on a loaded machine: aarch64 291 s, the gvcp
# lane 280, lib-asan 216, daemon-v4l2 170, tool 146, daemon-v4l2-asan
# 127, daemon-asan 100, coarse 98; the rest 60 s or less each)
CHECK_FIRST := check-aarch64 check-lane-gvcp check-lib-asan check-daemon-v4l2 check-tool \
               check-daemon-v4l2-asan check-daemon-asan check-coarse
CHECK_RUN := $(filter-out $(CHECK_LANED),$(filter $(CHECK_STEPS) $(CHECK_LANES:%=check-lane-%),$(CHECK_FIRST))) \
             $(filter-out $(CHECK_FIRST) $(CHECK_LANED),$(CHECK_STEPS) $(CHECK_LANES:%=check-lane-%))
.PHONY: check-run $(CHECK_LANES:%=check-lane-%)
check-run: $(CHECK_RUN)
# (a make of its own without the jobserver: its steps one at a time, so
# MAKEFLAGS without -j and --jobserver-auth; command-line variables kept)
$(CHECK_LANES:%=check-lane-%): check-lane-%:
	@MAKEFLAGS="$(filter-out -j% --jobserver%,$(MAKEFLAGS))" \
	 $(MAKE) --no-print-directory -k -j1 $(filter $(CHECK_STEPS),$(CHECK_LANE_$*))

deps:
	tests/deps.sh install all

# The quick start on a new minimal bookworm root (debootstrap, chroot; root
# only, 15-40 minutes): tests/fresh-machine.sh.
.PHONY: check-fresh
check-fresh:
	tests/fresh-machine.sh

# ---------------------------------------------------------------------------
# Benchmarks: figures, not pass/fail.
# ---------------------------------------------------------------------------
BENCH_BIN := $(BUILD)/bench/bench_lib
$(BENCH_BIN): tests/bench/bench_lib.c tests/lib/support.c $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O3 -Itests/lib $< tests/lib/support.c $(host_LIB) -lm -o $@

.PHONY: bench-lib
bench-lib: $(BENCH_BIN)
	$(BENCH_BIN)

# The accuracy study of issue 12 (tests/bench/bench_accuracy.c): about a
# minute on one core; every cell of its grid goes to accuracy_cells.csv.
ACC_BIN := $(BUILD)/bench/bench_accuracy
$(ACC_BIN): tests/bench/bench_accuracy.c tests/lib/support.c tests/lib/support.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O3 -Itests/lib $< tests/lib/support.c $(host_LIB) -lm -o $@

.PHONY: bench-accuracy
bench-accuracy: $(ACC_BIN)
	$(ACC_BIN) $(BUILD)/bench/accuracy_cells.csv
BENCH_STEPS := bench-lib bench-accuracy $(BENCH_STEPS)

# Per pipe and per contour figures of bench-accuracy's paper scene (not in
# BENCH_STEPS: a diagnosis, about a minute per light row)
PAPER_CONTOURS_BIN := $(BUILD)/bench/diag_paper
$(PAPER_CONTOURS_BIN): tests/bench/diag_paper.c tests/lib/support.c tests/lib/support.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O3 -Ilib -Itests/lib $< tests/lib/support.c $(host_LIB) -lm -o $@

.PHONY: bench-paper-contours
bench-paper-contours: $(PAPER_CONTOURS_BIN)
	$(PAPER_CONTOURS_BIN) 2

bench:
	@tests/deps.sh check $(DEPS_BUILD)
	@$(MAKE) --no-print-directory bench-steps
bench-steps: $(BENCH_STEPS)

# ---------------------------------------------------------------------------
demo:
	@tests/deps.sh ensure demo
	@$(MAKE) --no-print-directory $(DEMO_TARGET)

clean:
	rm -rf $(BUILD)

.PHONY: build-all
