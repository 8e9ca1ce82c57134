# The frame path against the memory limit (issue 17): tests/bench/bench_frame.c.
# `make bench-frame` alone; part of `make bench`. Renders its frames once
# into $(BUILD)/bench/frames.raw (about a minute), then seconds per run.
BENCH_FRAME_BIN := $(BUILD)/bench/bench_frame
$(BENCH_FRAME_BIN): tests/bench/bench_frame.c tests/lib/support.c tests/lib/support.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itests/lib $< tests/lib/support.c $(host_LIB) -lm -o $@

# The frame's bytes actually read, as distinct 64-byte lines (issue 17):
# callgrind's cache model on one solve of each path (tests/bench/
# frame_lines.sh, a few seconds), into $(BUILD)/bench/lines.txt, which
# bench-frame prints and divides by the bandwidth; counted again when the
# library changes (bench_frame links it). Without valgrind, bench-frame
# keeps its whole-row upper bound.
$(BUILD)/bench/lines.txt: $(BENCH_FRAME_BIN) $(BUILD)/bench/frames.raw tests/bench/frame_lines.sh
	tests/bench/frame_lines.sh $(BENCH_FRAME_BIN) $(BUILD)/bench

.PHONY: bench-frame bench-frame-lines
bench-frame-lines: $(BUILD)/bench/lines.txt
bench-frame: $(BENCH_FRAME_BIN) $(BUILD)/bench/lines.txt
	$(BENCH_FRAME_BIN) $(BUILD)/bench
BENCH_STEPS += bench-frame

# The cached frames alone (bench-aarch64 reads them): rendered when missing.
$(BUILD)/bench/frames.raw: | $(BENCH_FRAME_BIN)
	$(BENCH_FRAME_BIN) $(BUILD)/bench load

# The coarse pass misses no pipe the whole-frame search finds (issue 17):
# the detection benchmark's generated frames (tests/bench/bench_detect.c,
# its own seed 7, 640 x 480 .. 2448 x 2048, clutter, faint pipes, 8..16 bit)
# solved both ways; a check step, a few minutes on one core.
.PHONY: check-coarse
check-coarse: $(BENCH_DETECT_BIN)
	@BENCH_DETECT_COARSE=1 $(RUN) "bench/coarse-misses-nothing" $(BENCH_DETECT_BIN) 60 20 7
CHECK_STEPS += check-coarse

# The side-by-side with a plain OpenCV pipeline (tests/bench/cv_baseline.cpp;
# OpenCV as cdsp_calib builds it, tools/calib.mk).
CV_BASELINE_BIN := $(BUILD)/bench/cv_baseline
$(CV_BASELINE_BIN): tests/bench/cv_baseline.cpp $(host_LIB)
	@mkdir -p $(@D)
	$(CALIB_CXX) -std=c++17 -Wall -Wextra -pedantic -Werror -Wshadow $(OPT) -g $(CALIB_CV_INC) -Iinclude \
	  $< $(host_LIB) $(CALIB_CV_LIBS) -o $@

.PHONY: bench-cv
bench-cv: $(CV_BASELINE_BIN) $(BUILD)/bench/frames.raw
	$(CV_BASELINE_BIN) $(BUILD)/bench
BENCH_STEPS += bench-cv
