# Instruction counts of the multi-pipe frame path on the paper's rack
# (issue 13): tests/bench/bench_rack.c; a build target for callgrind, not
# a bench step (its figures are counts, read under valgrind):
#   build/bench/bench_rack build/bench load   (renders once, ~10 s)
#   valgrind --tool=callgrind --dump-instr=no \
#     --toggle-collect=measured_solve build/bench/bench_rack build/bench full|track [REFINE_STEP [POINT_FIT]]
BENCH_RACK_BIN := $(BUILD)/bench/bench_rack
# the scene is tools/tool_rack_scene.c, the tool's own (defined once; it
# needs only lib/'s cdsp.h)
$(BENCH_RACK_BIN): tests/bench/bench_rack.c tests/lib/support.c tests/lib/support.h \
                   tools/tool_rack_scene.c tools/tool_rack_scene.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itests/lib -Itools $< tests/lib/support.c tools/tool_rack_scene.c $(host_LIB) \
	    -lm -o $@

# The per-point estimator study (docs/method.md §3a, the point fit): a
# diagnostic, built with everything so that it keeps compiling.
PROBE_POINT_FIT_BIN := $(BUILD)/bench/probe_point_fit
$(PROBE_POINT_FIT_BIN): tests/bench/probe_point_fit.c tests/lib/support.c tests/lib/support.h \
                        tools/tool_rack_scene.c tools/tool_rack_scene.h $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -D_DEFAULT_SOURCE -Itests/lib -Itools $< tests/lib/support.c tools/tool_rack_scene.c \
	    $(host_LIB) -lm -o $@
ALL_TARGETS += $(PROBE_POINT_FIT_BIN)
