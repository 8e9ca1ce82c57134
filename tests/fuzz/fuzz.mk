# tests/fuzz/fuzz.mk: libFuzzer targets (clang -fsanitize=fuzzer with
# ASan/UBSan) for every parser and entry point that takes outside data:
#   image-pgm, image-png  frame readers (host/image.c)
#   calib                 camera_info YAML reader (host/calib.c)
#   config                cdspd's config file and --set (daemon/config.c)
#   listen                a UDP datagram as `cdsp_tool listen` prints it
#   export                the JSON records `cdsp_tool export` reads
#   overlay               overlay drawing of points/lines anywhere
#   frame                 libcdsp on arbitrary frames and parameters
#   points                libcdsp's geometric entry points on arbitrary numbers
#   mavlink               the MAVLink encoder's inputs, its frames decoded back,
#                         received byte streams, the mavlink key's URLs
# Seeds and regression inputs (regress-*: every hostile input of issue 16 and
# every crash fuzzing found) are in tests/fuzz/corpus/TARGET/.
#
# make check: each target replays its corpus and runs a bounded number of
# executions (fuzz_RUNS_<target>, seeded: the same inputs every time) as a
# check step. make fuzz: each target for FUZZ_SECONDS (default 60), its
# corpus growing in build/fuzz/corpus/TARGET, crashes in build/fuzz/crashes/.
# Names start with fuzz_.

fuzz_DIR := $(BUILD)/fuzz
fuzz_OBJ_DIR := $(fuzz_DIR)/obj
fuzz_SAN := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -g
fuzz_CFLAGS := $(BASE_CFLAGS) -O1 $(fuzz_SAN) -fsanitize=fuzzer-no-link
# the host library's packages (host/host.mk), and cairo and fontconfig for
# the overlay's drawing
fuzz_PKGS := $(HOSTLIB_PKGS) cairo fontconfig
fuzz_SYS := $(patsubst -I%,-isystem %,$(shell pkg-config --cflags $(fuzz_PKGS) 2>/dev/null))
# a part's objects see the host library and their own part only; the
# harnesses see all three
fuzz_INC := $(HOSTLIB_INC) -Itools -Idaemon -Itests/fuzz $(fuzz_SYS)
fuzz_TOOL_INC := $(HOSTLIB_INC) -Itools $(fuzz_SYS)
fuzz_DAEMON_INC := $(HOSTLIB_INC) -Idaemon $(fuzz_SYS)
fuzz_LIBS := $(shell pkg-config --libs $(fuzz_PKGS) 2>/dev/null || echo $(HOSTLIB_PKG_FALLBACK) -lcairo -lfontconfig) \
             -lpthread -lm

# libcdsp instrumented for coverage (build/fuzz/libcdsp.a)
fuzz_LIB_CFLAGS := $(fuzz_CFLAGS)
$(eval $(call lib_variant,fuzz,$(CLANG),fuzz_LIB_CFLAGS))

# libcdsp_host instrumented the same way (host/host.mk builds it)
fuzz_HOST_LIB := $(HOSTLIB_FUZZ_LIB)
# config.o refers to the file source (cdspd_config_finish finds a
# recording's calibration) and to the MAVLink output's URL parser and mount
# presets: those objects come along
fuzz_DAEMON_OBJ := $(patsubst %,$(fuzz_OBJ_DIR)/daemon/%.o,config log src_file source pool \
                     sim_path src_sim mavlink mount mavout stats)
$(fuzz_OBJ_DIR)/daemon/%.o: daemon/%.c
	@mkdir -p $(@D)
	$(CLANG) $(fuzz_CFLAGS) $(fuzz_DAEMON_INC) -c $< -o $@
$(fuzz_OBJ_DIR)/tools/%.o: tools/%.c
	@mkdir -p $(@D)
	$(CLANG) $(fuzz_CFLAGS) $(fuzz_TOOL_INC) -c $< -o $@
$(fuzz_OBJ_DIR)/image-pgm.o: tests/fuzz/fuzz_image.c
	@mkdir -p $(@D)
	$(CLANG) $(fuzz_CFLAGS) $(fuzz_INC) -DFUZZ_FORMAT=1 -c $< -o $@
$(fuzz_OBJ_DIR)/image-png.o: tests/fuzz/fuzz_image.c
	@mkdir -p $(@D)
	$(CLANG) $(fuzz_CFLAGS) $(fuzz_INC) -DFUZZ_FORMAT=2 -c $< -o $@
$(fuzz_OBJ_DIR)/%.o: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_input.h
	@mkdir -p $(@D)
	$(CLANG) $(fuzz_CFLAGS) $(fuzz_INC) -c $< -o $@

# target: the objects it links beside its harness
fuzz_TARGETS := image-pgm image-png calib config listen export overlay frame points mavlink
fuzz_DEPS_image-pgm := $(fuzz_HOST_LIB)
fuzz_DEPS_image-png := $(fuzz_HOST_LIB)
fuzz_DEPS_calib := $(fuzz_HOST_LIB)
fuzz_DEPS_config := $(fuzz_DAEMON_OBJ) $(fuzz_HOST_LIB)
fuzz_DEPS_listen := $(fuzz_OBJ_DIR)/tools/listen.o $(fuzz_HOST_LIB)
fuzz_DEPS_export := $(fuzz_OBJ_DIR)/tools/tool_export.o $(fuzz_OBJ_DIR)/tools/tool_common.o \
                    $(fuzz_HOST_LIB)
fuzz_DEPS_overlay := $(fuzz_OBJ_DIR)/tools/tool_overlay.o $(fuzz_OBJ_DIR)/tools/tool_caption.o $(fuzz_HOST_LIB)
fuzz_DEPS_frame :=
fuzz_DEPS_points :=
fuzz_DEPS_mavlink := $(fuzz_DAEMON_OBJ) $(fuzz_HOST_LIB)

# Executions per target in make check, the corpus replay included, chosen
# for ~40 s in all under ASan/UBSan on this 2-core machine (exec/s measured
# with `make check-fuzz`: pgm ~20k, png 5k, calib 1.3k, config 500, listen
# 6.6k, export ~5k, overlay 330, frame 60, points 375). FUZZ_RUNS overrides.
fuzz_RUNS_image-pgm := 20000
fuzz_RUNS_image-png := 10000
fuzz_RUNS_calib := 4000
fuzz_RUNS_config := 5000
fuzz_RUNS_listen := 20000
fuzz_RUNS_export := 4000
fuzz_RUNS_overlay := 1000
fuzz_RUNS_frame := 600
fuzz_RUNS_points := 2000
fuzz_RUNS_mavlink := 10000
fuzz_MAXLEN_frame := 20000
FUZZ_SECONDS ?= 60

fuzz_BIN = $(fuzz_DIR)/fuzz_$(1)
fuzz_BINS := $(foreach t,$(fuzz_TARGETS),$(call fuzz_BIN,$(t)))
# -malloc_limit_mb: one allocation beyond it is a finding (the 2 GiB PNG);
# -close_fd_mask=3: the programs' own messages are silenced, libFuzzer's
# and the sanitizers' reports are kept.
fuzz_FLAGS = -seed=1 -close_fd_mask=3 -malloc_limit_mb=512 -rss_limit_mb=2048 -timeout=20 \
             -max_len=$(or $(fuzz_MAXLEN_$(1)),4096) -print_final_stats=1

define fuzz_target
$(call fuzz_BIN,$(1)): $(fuzz_OBJ_DIR)/$(1).o $(fuzz_DEPS_$(1)) $(fuzz_LIB)
	$(CLANG) $(fuzz_SAN) -fsanitize=fuzzer $$^ $(fuzz_LIBS) -o $$@

.PHONY: check-fuzz-$(1) fuzz-$(1)
check-fuzz-$(1): $(call fuzz_BIN,$(1))
	@rm -rf $(fuzz_DIR)/check/$(1) && mkdir -p $(fuzz_DIR)/check/$(1) $(fuzz_DIR)/crashes
	@$(RUN) "fuzz/$(1)" $(call fuzz_BIN,$(1)) $(call fuzz_FLAGS,$(1)) \
	    -runs=$(or $(FUZZ_RUNS),$(fuzz_RUNS_$(1))) -verbosity=0 -print_funcs=0 -artifact_prefix=$(fuzz_DIR)/crashes/$(1)- \
	    $(fuzz_DIR)/check/$(1) tests/fuzz/corpus/$(1)

fuzz-$(1): $(call fuzz_BIN,$(1))
	@mkdir -p $(fuzz_DIR)/corpus/$(1) $(fuzz_DIR)/crashes
	$(call fuzz_BIN,$(1)) $(call fuzz_FLAGS,$(1)) -max_total_time=$(FUZZ_SECONDS) \
	    -artifact_prefix=$(fuzz_DIR)/crashes/$(1)- $(fuzz_DIR)/corpus/$(1) tests/fuzz/corpus/$(1)
endef
$(foreach t,$(fuzz_TARGETS),$(eval $(call fuzz_target,$(t))))

-include $(wildcard $(fuzz_OBJ_DIR)/*.d $(fuzz_OBJ_DIR)/*/*.d)

.PHONY: check-fuzz fuzz fuzz-build
fuzz-build: $(fuzz_BINS)
check-fuzz: $(foreach t,$(fuzz_TARGETS),check-fuzz-$(t))
# one target after the other: each gets the machine for FUZZ_SECONDS
fuzz: $(fuzz_BINS)
	@for t in $(fuzz_TARGETS); do $(MAKE) --no-print-directory fuzz-$$t || exit 1; done
CHECK_STEPS += check-fuzz
