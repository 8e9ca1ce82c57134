# tools/tool.mk: build/libcdsp_host.a (frame files, calibration YAML, JSON
# records: shared by cdsp_tool and cdspd), build/cdsp_tool, and their checks.
# Included by the top-level Makefile; variables and targets start with tool_.

tool_PKGS     := yaml-0.1 spng json-c libjpeg libtiff-4 cairo fontconfig
tool_PKG_CFLAGS := $(shell pkg-config --cflags $(tool_PKGS) 2>/dev/null)
# libcsv (reading solve's CSV back in plot and compare) has no .pc file
tool_PKG_LIBS := $(shell pkg-config --libs $(tool_PKGS) 2>/dev/null || \
                   echo -lyaml -lspng -ljson-c -ljpeg -ltiff -lcairo -lfontconfig) -lcsv

tool_HOST_SRC := $(sort $(wildcard tools/common/*.c))
tool_HOST_HDR := tools/common/cdsp_host.h
tool_CFLAGS   := $(HOST_CFLAGS) -Itools/common $(tool_PKG_CFLAGS)

# --- libcdsp_host.a (host build) and an ASan/UBSan twin for the tests -------
tool_HOST_OBJ := $(patsubst tools/common/%.c,$(BUILD)/tools/common/%.o,$(tool_HOST_SRC))
CDSP_HOST_LIB := $(BUILD)/libcdsp_host.a

$(BUILD)/tools/common/%.o: tools/common/%.c
	@mkdir -p $(@D)
	$(CC) $(tool_CFLAGS) -c $< -o $@

$(CDSP_HOST_LIB): $(tool_HOST_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && $(AR) rcs $@ $^

tool_ASAN_CFLAGS := $(ASAN_CFLAGS) -Itools/common $(tool_PKG_CFLAGS)
tool_ASAN_OBJ := $(patsubst tools/common/%.c,$(BUILD)/tools-asan/common/%.o,$(tool_HOST_SRC))
tool_ASAN_LIB := $(BUILD)/tools-asan/libcdsp_host.a

$(BUILD)/tools-asan/common/%.o: tools/common/%.c
	@mkdir -p $(@D)
	$(CLANG) $(tool_ASAN_CFLAGS) -c $< -o $@

$(tool_ASAN_LIB): $(tool_ASAN_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && $(AR) rcs $@ $^

# --- cdsp_tool ---------------------------------------------------------------
tool_SRC := tools/cdsp_tool.c $(sort $(wildcard tools/tool_*.c))
tool_OBJ := $(patsubst tools/%.c,$(BUILD)/tools/%.o,$(tool_SRC))
tool_BIN := $(BUILD)/cdsp_tool

$(BUILD)/tools/%.o: tools/%.c
	@mkdir -p $(@D)
	$(CC) $(tool_CFLAGS) -c $< -o $@

# `cdsp_tool listen` is tools/listen.c with the daemon's protocol decoder,
# built by daemon/daemon.mk (included before this file) as daemon_LISTEN_OBJS.
$(tool_BIN): $(tool_OBJ) $(daemon_LISTEN_OBJS) $(CDSP_HOST_LIB) $(host_LIB)
	$(CC) $(tool_CFLAGS) $(tool_OBJ) $(daemon_LISTEN_OBJS) $(CDSP_HOST_LIB) $(host_LIB) \
	    $(tool_PKG_LIBS) -lpthread -lm -o $@

ALL_TARGETS += $(CDSP_HOST_LIB) $(tool_BIN)

-include $(tool_HOST_OBJ:.o=.d) $(tool_ASAN_OBJ:.o=.d) $(tool_OBJ:.o=.d)

# --- tests ---------------------------------------------------------------------
# Unit suites of tools/common (cmocka), built twice: plain and ASan/UBSan.
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
	$(CLANG) $(tool_ASAN_CFLAGS) $(CFLAGS_EXTRA) -c $< -o $@
# the listener (tools/listen.c + daemon/proto.c) in each sanitizer build too
tool_ASAN_LISTEN_OBJ := $(BUILD)/tools-asan/listen.o $(BUILD)/tools-asan/proto.o
$(BUILD)/tools-asan/proto.o: daemon/proto.c
	@mkdir -p $(@D)
	$(CLANG) $(tool_ASAN_CFLAGS) -Idaemon -c $< -o $@
$(BUILD)/tools-asan/listen.o: CFLAGS_EXTRA := -Idaemon
$(tool_ASAN_BIN): $(tool_ASAN_TOOL_OBJ) $(tool_ASAN_LISTEN_OBJ) $(tool_ASAN_LIB) $(asan_LIB)
	$(CLANG) $(tool_ASAN_CFLAGS) $(tool_ASAN_TOOL_OBJ) $(tool_ASAN_LISTEN_OBJ) $(tool_ASAN_LIB) \
	  $(asan_LIB) $(tool_PKG_LIBS) -lpthread -lm -o $@

tool_TSAN_CFLAGS := $(BASE_CFLAGS) -O1 -g -fsanitize=thread -Itools/common $(tool_PKG_CFLAGS)
tool_TSAN_BIN := $(BUILD)/tools-tsan/cdsp_tool
tool_TSAN_OBJ := $(patsubst tools/%.c,$(BUILD)/tools-tsan/%.o,$(tool_SRC))
$(BUILD)/tools-tsan/%.o: tools/%.c
	@mkdir -p $(@D)
	$(CLANG) $(tool_TSAN_CFLAGS) $(CFLAGS_EXTRA) -c $< -o $@
tool_TSAN_LISTEN_OBJ := $(BUILD)/tools-tsan/listen.o $(BUILD)/tools-tsan/proto.o
$(BUILD)/tools-tsan/proto.o: daemon/proto.c
	@mkdir -p $(@D)
	$(CLANG) $(tool_TSAN_CFLAGS) -Idaemon -c $< -o $@
$(BUILD)/tools-tsan/listen.o: CFLAGS_EXTRA := -Idaemon
$(tool_TSAN_BIN): $(tool_TSAN_OBJ) $(tool_TSAN_LISTEN_OBJ) $(CDSP_HOST_LIB) $(host_LIB)
	$(CLANG) $(tool_TSAN_CFLAGS) $(tool_TSAN_OBJ) $(tool_TSAN_LISTEN_OBJ) $(CDSP_HOST_LIB) \
	  $(host_LIB) $(tool_PKG_LIBS) -lpthread -lm -o $@

-include $(tool_ASAN_TOOL_OBJ:.o=.d) $(tool_TSAN_OBJ:.o=.d) $(tool_ASAN_LISTEN_OBJ:.o=.d) \
         $(tool_TSAN_LISTEN_OBJ:.o=.d)

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
