# tools/tool.mk: build/cdsp_tool and its checks (the unit suites of the
# host library it links, tests/tool/test_host_*, run here too). It links
# build/libcdsp_host.a and its twins (host/host.mk) and includes nothing of
# daemon/. Included by the top-level Makefile; variables and targets start
# with tool_.

# the host library's packages, and cairo and fontconfig for the overlay
tool_PKGS     := $(HOSTLIB_PKGS) cairo fontconfig
tool_PKG_CFLAGS := $(shell pkg-config --cflags $(tool_PKGS) 2>/dev/null)
# libcsv (reading solve's CSV back in plot and compare) has no .pc file
tool_PKG_LIBS := $(shell pkg-config --libs $(tool_PKGS) 2>/dev/null || \
                   echo $(HOSTLIB_PKG_FALLBACK) -lcairo -lfontconfig) -lcsv

tool_CFLAGS   := $(HOST_CFLAGS) $(HOSTLIB_INC) $(tool_PKG_CFLAGS)
tool_ASAN_CFLAGS := $(ASAN_CFLAGS) $(HOSTLIB_INC) $(tool_PKG_CFLAGS)
tool_ASAN_LIB := $(HOSTLIB_ASAN_LIB)

# --- cdsp_tool ---------------------------------------------------------------
tool_SRC := tools/cdsp_tool.c tools/listen.c $(sort $(wildcard tools/tool_*.c))
tool_OBJ := $(patsubst tools/%.c,$(BUILD)/tools/%.o,$(tool_SRC))
tool_BIN := $(BUILD)/cdsp_tool

$(BUILD)/tools/%.o: tools/%.c
	@mkdir -p $(@D)
	$(CC) $(tool_CFLAGS) -c $< -o $@

# `cdsp_tool listen` (tools/listen.c) decodes with the host library's
# protocol decoder (host/proto.c).
$(tool_BIN): $(tool_OBJ) $(CDSP_HOST_LIB) $(host_LIB)
	$(CC) $(tool_CFLAGS) $(tool_OBJ) $(CDSP_HOST_LIB) $(host_LIB) \
	    $(tool_PKG_LIBS) -lpthread -lm -o $@

ALL_TARGETS += $(tool_BIN)

-include $(tool_OBJ:.o=.d)

# --- tests ---------------------------------------------------------------------
# Unit suites of the host library (cmocka), built twice: plain and ASan/UBSan.
tool_UNIT_SRC := $(sort $(wildcard tests/tool/test_host_*.c))
tool_UNIT     := $(patsubst tests/tool/%.c,$(BUILD)/tests/tool/%,$(tool_UNIT_SRC))
tool_UNIT_ASAN := $(patsubst tests/tool/%.c,$(BUILD)/tests/tool-asan/%,$(tool_UNIT_SRC))

$(BUILD)/tests/tool/test_host_%: tests/tool/test_host_%.c tests/tool/tool_test.h $(CDSP_HOST_LIB) $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(tool_CFLAGS) -Itests/tool $< $(CDSP_HOST_LIB) $(host_LIB) $(tool_PKG_LIBS) -lcmocka -lm -o $@

$(BUILD)/tests/tool-asan/test_host_%: tests/tool/test_host_%.c tests/tool/tool_test.h $(tool_ASAN_LIB) $(asan_LIB)
	@mkdir -p $(@D)
	$(CLANG) $(tool_ASAN_CFLAGS) -Itests/tool $< $(tool_ASAN_LIB) $(asan_LIB) $(tool_PKG_LIBS) -lcmocka -lm -o $@

# End-to-end suite: runs build/cdsp_tool on frames it simulated itself.
tool_E2E := $(BUILD)/tests/tool/test_tool_cli
$(tool_E2E): tests/tool/test_tool_cli.c tests/tool/tool_test.h $(CDSP_HOST_LIB) $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(tool_CFLAGS) -Itests/tool $< $(CDSP_HOST_LIB) $(host_LIB) $(tool_PKG_LIBS) -lcmocka -lm -o $@

# cdsp_tool itself under ASan/UBSan (libcdsp and libcdsp_host too) and
# under TSan (the --threads pipeline), for the same end-to-end suite.
tool_ASAN_BIN := $(BUILD)/tools-asan/cdsp_tool
tool_ASAN_TOOL_OBJ := $(patsubst tools/%.c,$(BUILD)/tools-asan/%.o,$(tool_SRC))
$(BUILD)/tools-asan/%.o: tools/%.c
	@mkdir -p $(@D)
	$(CLANG) $(tool_ASAN_CFLAGS) -c $< -o $@
$(tool_ASAN_BIN): $(tool_ASAN_TOOL_OBJ) $(tool_ASAN_LIB) $(asan_LIB)
	$(CLANG) $(tool_ASAN_CFLAGS) $(tool_ASAN_TOOL_OBJ) $(tool_ASAN_LIB) \
	  $(asan_LIB) $(tool_PKG_LIBS) -lpthread -lm -o $@

# (the host library and libcdsp uninstrumented, as before the move: the
# threads under test are cdsp_tool's own)
tool_TSAN_CFLAGS := $(BASE_CFLAGS) -O1 -g -fsanitize=thread $(HOSTLIB_INC) $(tool_PKG_CFLAGS)
tool_TSAN_BIN := $(BUILD)/tools-tsan/cdsp_tool
tool_TSAN_OBJ := $(patsubst tools/%.c,$(BUILD)/tools-tsan/%.o,$(tool_SRC))
$(BUILD)/tools-tsan/%.o: tools/%.c
	@mkdir -p $(@D)
	$(CLANG) $(tool_TSAN_CFLAGS) -c $< -o $@
$(tool_TSAN_BIN): $(tool_TSAN_OBJ) $(CDSP_HOST_LIB) $(host_LIB)
	$(CLANG) $(tool_TSAN_CFLAGS) $(tool_TSAN_OBJ) $(CDSP_HOST_LIB) \
	  $(host_LIB) $(tool_PKG_LIBS) -lpthread -lm -o $@

-include $(tool_ASAN_TOOL_OBJ:.o=.d) $(tool_TSAN_OBJ:.o=.d)

# Sanitizer findings exit with statuses the suite never expects (66, 86, 87).
tool_SAN_ENV := ASAN_OPTIONS=detect_leaks=1:exitcode=86 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:exitcode=87 \
  TSAN_OPTIONS=halt_on_error=1:exitcode=66

.PHONY: check-tool
check-tool: $(tool_UNIT) $(tool_UNIT_ASAN) $(tool_E2E) $(tool_BIN) $(tool_ASAN_BIN) $(tool_TSAN_BIN)
	@for t in $(tool_UNIT); do $(RUN) "tool/$$(basename $$t)" $$t || exit 1; done
	@for t in $(tool_UNIT_ASAN); do $(tool_SAN_ENV) \
	  $(RUN) "tool-asan/$$(basename $$t)" $$t || exit 1; done
	@CDSP_TOOL=$(tool_BIN) $(RUN) "tool/test_tool_cli" $(tool_E2E)
	@CDSP_TOOL=$(tool_ASAN_BIN) $(tool_SAN_ENV) $(RUN) "tool-asan/test_tool_cli" $(tool_E2E)
	@CDSP_TOOL=$(tool_TSAN_BIN) $(tool_SAN_ENV) $(RUN) "tool-tsan/test_tool_cli" $(tool_E2E)

CHECK_STEPS += check-tool

# The paper's accuracy study (figures, not pass/fail): `make bench`.
.PHONY: bench-tool
bench-tool: $(tool_BIN)
	$(tool_BIN) bench --out $(BUILD)/bench-tool
BENCH_STEPS += bench-tool
# The paper's real experiment rendered (issue 13): rack detection and the
# spacing RMSE table (about 20 frames of 2448 x 2048, a few minutes).
.PHONY: bench-rack
bench-rack: $(tool_BIN)
	$(tool_BIN) bench --rack --out $(BUILD)/bench-rack
BENCH_STEPS += bench-rack
# And as a check (issue 13): every pipe of the rendered rack found, no gap
# taken for a pipe, one frame per group (a few minutes; tests/tool/rack_check.sh).
.PHONY: check-rack
check-rack: $(tool_BIN)
	@$(RUN) "tool/rack-every-pipe" tests/tool/rack_check.sh $(tool_BIN) $(BUILD)/check-rack
CHECK_STEPS += check-rack
