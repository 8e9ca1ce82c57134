# AArch64 (issue 17): libcdsp and the library's unit tests cross-built with
# Debian's gcc-aarch64-linux-gnu and run under qemu-user (.ci/packages.d/
# aarch64.txt). The library is built as the host's (-O3, NEON: every AArch64
# has it, so lib/edges_simd.c's NEON form is what the scans use there); the
# tests are the host's sources, linked against tests/aarch64/cmocka.h (the
# subset of cmocka they use: Debian has no arm64 libcmocka without
# multiarch). tests/lib/test_edges_scan.c compares the NEON candidate test
# and the whole scan with the portable reference bit for bit.
#   make check-aarch64   build and run the subset below (make check)
#   make check-aarch64-all  every suite (ten minutes under emulation here)
#   make bench-aarch64   instructions the frame path executes there (emulated
#                        time means nothing): tests/aarch64/count.sh
A64_CC     ?= aarch64-linux-gnu-gcc
A64_SYSROOT ?= /usr/aarch64-linux-gnu
A64_QEMU   ?= qemu-aarch64 -L $(A64_SYSROOT)
A64_CFLAGS := $(BASE_CFLAGS) $(OPT) -g
$(eval $(call lib_variant,a64,$(A64_CC),A64_CFLAGS))

A64_UTESTS := $(patsubst tests/lib/%.c,$(BUILD)/a64/utests/%,$(LIB_TEST))
$(BUILD)/a64/utests/%: tests/lib/%.c tests/aarch64/cmocka.h $(BUILD)/a64/tests/support.o $(a64_LIB)
	@mkdir -p $(@D)
	$(A64_CC) $(A64_CFLAGS) -Itests/aarch64 -Itests/lib $< $(BUILD)/a64/tests/support.o $(a64_LIB) -lm -o $@

# make check runs the suites where the architecture matters (the scans and
# their NEON form, the geometry's floating point) and leaves the long
# statistical ones (covariance, frame, points, profile, render, multi:
# portable C99 already run on x86-64 in double and float and on Cortex-M)
# to check-aarch64-all: under emulation on this 2-core machine the whole
# set took 10 minutes, this subset about 3 (test_edges_scan 2 of them).
A64_CHECK := $(filter $(patsubst %,$(BUILD)/a64/utests/test_%,edges edges_scan camera axis lines svd3 \
               status rng),$(A64_UTESTS))
.PHONY: check-aarch64 check-aarch64-all
check-aarch64: $(A64_CHECK)
	@for t in $^; do $(RUN) "aarch64/$$(basename $$t)" $(A64_QEMU) $$t || exit 1; done
check-aarch64-all: $(A64_UTESTS)
	@for t in $^; do $(RUN) "aarch64/$$(basename $$t)" $(A64_QEMU) $$t || exit 1; done
CHECK_STEPS += check-aarch64

A64_BENCH := $(BUILD)/a64/bench/bench_frame
$(A64_BENCH): tests/bench/bench_frame.c tests/lib/support.c tests/lib/support.h $(a64_LIB)
	@mkdir -p $(@D)
	$(A64_CC) $(A64_CFLAGS) -Itests/lib $< tests/lib/support.c $(a64_LIB) -lm -o $@

# `make bench` checks only the build groups: without the cross packages
# this step says so and is skipped (`make check` installs them).
.PHONY: bench-aarch64 bench-aarch64-run
bench-aarch64:
	@if tests/deps.sh check aarch64 >/dev/null 2>&1; then $(MAKE) --no-print-directory bench-aarch64-run; \
	 else echo "bench-aarch64: skipped: $$(tests/deps.sh check aarch64 2>&1 | head -1)"; fi
bench-aarch64-run: $(A64_BENCH) $(BUILD)/bench/frames.raw
	tests/aarch64/count.sh "$(A64_QEMU)" $(A64_BENCH) $(BUILD)/bench
BENCH_STEPS += bench-aarch64
