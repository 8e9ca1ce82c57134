# Detection benchmark (issue 10): found rate, false positives and the
# confidence calibration on a seeded generated set of rendered frames.
# `make bench-detect` alone; part of `make bench`. A few minutes on one core.
BENCH_DETECT_BIN := $(BUILD)/bench/bench_detect
$(BENCH_DETECT_BIN): tests/bench/bench_detect.c tests/lib/support.c tests/lib/support.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O3 -Itests/lib $< tests/lib/support.c $(host_LIB) -lm -o $@

.PHONY: bench-detect
bench-detect: $(BENCH_DETECT_BIN)
	$(BENCH_DETECT_BIN) 300 100 1
BENCH_STEPS += bench-detect
