# The frame path against the memory limit (issue 17): tests/bench/bench_frame.c.
# `make bench-frame` alone; part of `make bench`. Renders its frames once
# into $(BUILD)/bench/frames.raw (about a minute), then seconds per run.
BENCH_FRAME_BIN := $(BUILD)/bench/bench_frame
$(BENCH_FRAME_BIN): tests/bench/bench_frame.c tests/lib/support.c tests/lib/support.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itests/lib $< tests/lib/support.c $(host_LIB) -lm -o $@

.PHONY: bench-frame
bench-frame: $(BENCH_FRAME_BIN)
	$(BENCH_FRAME_BIN) $(BUILD)/bench
BENCH_STEPS += bench-frame

# The cached frames alone (bench-aarch64 reads them): rendered when missing.
$(BUILD)/bench/frames.raw: | $(BENCH_FRAME_BIN)
	$(BENCH_FRAME_BIN) $(BUILD)/bench load
