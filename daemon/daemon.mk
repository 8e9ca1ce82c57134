# daemon/daemon.mk: cdspd, the capture daemon (docs/cdspd.md), the tests
# (tests/daemon/), `make bench`'s bench-daemon and `make demo`; its
# sanitizer builds and their checks in daemon/sanitize.mk, included at the
# end. cdspd links build/libcdsp_host.a (host/host.mk: the protocol encoder
# of docs/protocol.md is there) and includes nothing of tools/. Names start
# with daemon_.
#
# Optional sources are built when their development package is there
# (pkg-config): aravis-0.8 (libaravis-dev), libv4l2 (libv4l-dev), libcamera
# (libcamera-dev); sd_notify with libsystemd (libsystemd-dev).

daemon_DIR := $(BUILD)/daemon
daemon_BIN := $(BUILD)/cdspd
# cdsp_tool (tools/tool.mk): the listener the end-to-end tests run
daemon_TOOL := $(BUILD)/cdsp_tool
CXX ?= g++

daemon_has = $(shell pkg-config --exists $(1) 2>/dev/null && echo yes)
# System headers (GLib's are not -pedantic clean): -isystem.
daemon_sys = $(patsubst -I%,-isystem %,$(shell pkg-config --cflags $(1) 2>/dev/null))

daemon_PKGS := $(HOSTLIB_PKGS)
daemon_DEFS :=
daemon_SRC := config.c log.c sim_path.c source.c src_sim.c src_file.c pool.c stats.c \
              sender.c record.c notify.c pipeline.c mavlink.c mount.c mavout.c pixfmt.c strips.c
daemon_CXX_SRC :=
daemon_LINK := $(CC)

ifeq ($(call daemon_has,aravis-0.8)$(wildcard daemon/src_aravis.c),yesdaemon/src_aravis.c)
daemon_PKGS += aravis-0.8
daemon_DEFS += -DCDSPD_HAVE_ARAVIS
daemon_SRC  += src_aravis.c
endif
ifeq ($(call daemon_has,libv4l2)$(wildcard daemon/src_v4l2.c),yesdaemon/src_v4l2.c)
daemon_PKGS += libv4l2
daemon_DEFS += -DCDSPD_HAVE_V4L2
daemon_SRC  += src_v4l2.c
endif
ifeq ($(call daemon_has,libcamera)$(wildcard daemon/src_libcamera.cpp),yesdaemon/src_libcamera.cpp)
daemon_PKGS += libcamera
daemon_DEFS += -DCDSPD_HAVE_LIBCAMERA
daemon_CXX_SRC += src_libcamera.cpp
daemon_LINK := $(CXX)
endif
ifeq ($(call daemon_has,libsystemd),yes)
daemon_PKGS += libsystemd
daemon_DEFS += -DCDSPD_HAVE_SYSTEMD
endif

daemon_CFLAGS := $(HOST_CFLAGS) $(HOSTLIB_INC) -Idaemon $(daemon_DEFS) $(call daemon_sys,$(daemon_PKGS))
daemon_CXXFLAGS := -std=c++17 -Wall -Wextra -pedantic -Werror -Wshadow -O2 -g -MMD -MP \
                   -Iinclude -Idaemon $(daemon_DEFS) $(call daemon_sys,$(daemon_PKGS))
daemon_LIBS = $(shell pkg-config --libs $(daemon_PKGS) 2>/dev/null || echo $(HOSTLIB_PKG_FALLBACK)) \
              -lpthread -lm

daemon_OBJ := $(patsubst %.c,$(daemon_DIR)/%.o,$(daemon_SRC)) \
              $(patsubst %.cpp,$(daemon_DIR)/%.o,$(daemon_CXX_SRC))
daemon_MAIN_OBJ := $(daemon_DIR)/cdspd.o
daemon_HOST_LIB := $(CDSP_HOST_LIB)

# Objects depend on the optional sources found: a stamp that changes with them.
daemon_STAMP := $(daemon_DIR)/features
daemon_FEATURES := $(strip $(daemon_DEFS))
# (-f: with no optional library the features are empty, and so is cat's
# output for a missing stamp; the stamp must exist all the same.)
$(shell mkdir -p $(daemon_DIR); [ -f $(daemon_STAMP) ] && \
        [ "$$(cat $(daemon_STAMP))" = "$(daemon_FEATURES)" ] || echo "$(daemon_FEATURES)" >$(daemon_STAMP))

$(daemon_DIR)/%.o: daemon/%.c $(daemon_STAMP)
	@mkdir -p $(@D)
	$(CC) $(daemon_CFLAGS) -c $< -o $@

$(daemon_DIR)/%.o: daemon/%.cpp $(daemon_STAMP)
	@mkdir -p $(@D)
	$(CXX) $(daemon_CXXFLAGS) -c $< -o $@

$(daemon_BIN): $(daemon_MAIN_OBJ) $(daemon_OBJ) $(daemon_HOST_LIB) $(host_LIB)
	$(daemon_LINK) $(daemon_MAIN_OBJ) $(daemon_OBJ) $(daemon_HOST_LIB) $(host_LIB) $(daemon_LIBS) -o $@

ALL_TARGETS += $(daemon_BIN)

-include $(daemon_OBJ:.o=.d) $(daemon_MAIN_OBJ:.o=.d)

# --- tests ---------------------------------------------------------------------
daemon_TDIR := $(BUILD)/tests/daemon
daemon_UNIT := $(daemon_TDIR)/test_proto $(daemon_TDIR)/test_config $(daemon_TDIR)/test_pool \
               $(daemon_TDIR)/test_mavlink $(daemon_TDIR)/test_mount \
               $(daemon_TDIR)/test_stats $(daemon_TDIR)/test_pixfmt $(daemon_TDIR)/test_strips
daemon_RX := $(daemon_TDIR)/cdspd_rx
daemon_MAVRX := $(daemon_TDIR)/mavlink_rx
daemon_FEED := $(daemon_TDIR)/v4l2_feed
daemon_NOTIFY := $(daemon_TDIR)/notify_rx
daemon_MCOUNT := $(daemon_TDIR)/malloc_count.so
$(daemon_MCOUNT): tests/daemon/malloc_count.c
	@mkdir -p $(@D)
	$(CC) $(filter-out -MMD -MP,$(HOST_CFLAGS)) -fPIC -shared $< -ldl -o $@
# The daemon's modules as an archive: a test links the ones it uses.
daemon_ARCHIVE := $(daemon_DIR)/libcdspd.a
$(daemon_ARCHIVE): $(daemon_OBJ)
	rm -f $@ && $(AR) rcs $@ $^

$(daemon_TDIR)/%.o: tests/daemon/%.c $(daemon_STAMP)
	@mkdir -p $(@D)
	$(CC) $(daemon_CFLAGS) -Itests/daemon -Itests/fakecam -c $< -o $@

$(daemon_TDIR)/%: $(daemon_TDIR)/%.o $(daemon_ARCHIVE) $(daemon_HOST_LIB) $(host_LIB)
	$(daemon_LINK) $< $(daemon_ARCHIVE) $(daemon_HOST_LIB) $(host_LIB) $(daemon_LIBS) -lcmocka -o $@

-include $(wildcard $(daemon_TDIR)/*.d)

.PHONY: check-daemon check-daemon-unit check-daemon-sim check-daemon-errors
check-daemon-unit: $(daemon_UNIT)
	@mkdir -p $(daemon_TDIR)/tmp
	@for t in $(daemon_UNIT); do CDSPD_TMP=$(daemon_TDIR)/tmp $(RUN) "daemon/$$(basename $$t)" $$t || exit 1; done

daemon_ENV = CDSPD=$(daemon_BIN) CDSPD_RX=$(daemon_RX) CDSP_LISTEN="$(daemon_TOOL) listen" \
             CDSPD_TMP=$(daemon_TDIR)/tmp

check-daemon-sim: $(daemon_BIN) $(daemon_RX) $(daemon_TOOL) $(daemon_MCOUNT)
	@$(daemon_ENV) MALLOC_COUNT=$(daemon_MCOUNT) $(RUN) "daemon/sim-e2e" tests/daemon/sim_e2e.sh

check-daemon-errors: $(daemon_BIN) $(daemon_RX) $(daemon_NOTIFY)
	@$(daemon_ENV) NOTIFY_RX=$(daemon_NOTIFY) $(RUN) "daemon/errors" tests/daemon/errors.sh

# issue 15's new-user behaviour (replay, bad frames, counters, listen, truth)
# and the one field list (JSON, CSV, docs/protocol.md, docs/cdsp_tool.md)
.PHONY: check-daemon-ux
daemon_FAKECAM := $(if $(filter -DCDSPD_HAVE_ARAVIS,$(daemon_DEFS)),$(BUILD)/fakecam/cdsp_fakecam)
check-daemon-ux: $(daemon_BIN) $(daemon_RX) $(daemon_TOOL) $(daemon_FAKECAM)
	@$(daemon_ENV) CDSP_TOOL=$(daemon_TOOL) FAKECAM=$(daemon_FAKECAM) $(RUN) "daemon/ux" tests/daemon/ux.sh
	@$(daemon_ENV) CDSP_TOOL=$(daemon_TOOL) $(RUN) "daemon/fields" tests/daemon/fields.sh

.PHONY: check-daemon-mavlink
check-daemon-mavlink: $(daemon_BIN) $(daemon_RX) $(daemon_MAVRX)
	@$(daemon_ENV) MAVLINK_RX=$(daemon_MAVRX) $(RUN) "daemon/mavlink" tests/daemon/mavlink_e2e.sh

daemon_CHECKS := check-daemon-unit check-daemon-sim check-daemon-errors check-daemon-ux \
                 check-daemon-mavlink

ifneq ($(filter -DCDSPD_HAVE_ARAVIS,$(daemon_DEFS)),)
.PHONY: check-daemon-aravis
check-daemon-aravis: $(daemon_BIN) $(daemon_RX) $(BUILD)/fakecam/cdsp_fakecam
	@$(daemon_ENV) $(RUN) "daemon/aravis-fakecam" tests/daemon/aravis_e2e.sh $(BUILD)/fakecam/cdsp_fakecam
daemon_CHECKS += check-daemon-aravis
# pixel formats, triggers, camera clock (issue 18)
.PHONY: check-daemon-aravis-formats
check-daemon-aravis-formats: $(daemon_BIN) $(daemon_RX) $(BUILD)/fakecam/cdsp_fakecam
	@$(daemon_ENV) $(RUN) "daemon/aravis-formats" tests/daemon/aravis_formats.sh $(BUILD)/fakecam/cdsp_fakecam
daemon_CHECKS += check-daemon-aravis-formats
endif
# the steps that run the fake GigE camera (its fixed GVCP port: one per
# machine): one at a time, the Makefile's gvcp lane (ux.sh: --list-cameras)
CHECK_LANE_gvcp += check-daemon-ux $(filter check-daemon-aravis%,$(daemon_CHECKS))

ifneq ($(filter -DCDSPD_HAVE_V4L2,$(daemon_DEFS)),)
.PHONY: check-daemon-v4l2
check-daemon-v4l2: $(daemon_BIN) $(daemon_RX) $(daemon_FEED)
	@CDSPD_TMP=$(daemon_TDIR)/tmp $(RUN) "daemon/v4l2-vivid-vm" tests/daemon/vm_v4l2.sh \
	    $(daemon_BIN) $(daemon_RX) $(daemon_FEED)
daemon_CHECKS += check-daemon-v4l2
endif

check-daemon: $(daemon_CHECKS)
CHECK_STEPS += $(daemon_CHECKS)

# --- bench -----------------------------------------------------------------------
.PHONY: bench-daemon
bench-daemon: $(daemon_BIN) $(daemon_RX) $(if $(filter -DCDSPD_HAVE_ARAVIS,$(daemon_DEFS)),$(BUILD)/fakecam/cdsp_fakecam)
	@$(daemon_ENV) tests/daemon/bench.sh $(if $(filter -DCDSPD_HAVE_ARAVIS,$(daemon_DEFS)),$(BUILD)/fakecam/cdsp_fakecam)
BENCH_STEPS += bench-daemon

# pixel-format conversion beside the solve (daemon/pixfmt.c is dependency-free)
daemon_BENCH_PIXFMT := $(BUILD)/bench/bench_pixfmt
$(daemon_BENCH_PIXFMT): tests/bench/bench_pixfmt.c daemon/pixfmt.c daemon/pixfmt.h \
                        tests/fakecam/fakecam_pixels.h tests/lib/support.c $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O3 -Itests/lib -Idaemon -Itests/fakecam $< daemon/pixfmt.c tests/lib/support.c \
	    $(host_LIB) -lm -o $@
.PHONY: bench-pixfmt
bench-pixfmt: $(daemon_BENCH_PIXFMT)
	$(daemon_BENCH_PIXFMT)
BENCH_STEPS += bench-pixfmt
ALL_TARGETS += $(daemon_BENCH_PIXFMT)

# --- demo ------------------------------------------------------------------------
# cdspd on its simulated camera and `cdsp_tool listen` beside it, printing
# poses until Ctrl-C, or for DEMO_SECONDS seconds.
DEMO_TARGET := daemon-demo
DEMO_SECONDS ?= 0
.PHONY: daemon-demo
daemon-demo: $(daemon_BIN) $(daemon_TOOL)
	@daemon/demo.sh $(daemon_BIN) $(daemon_TOOL) $(DEMO_SECONDS)
.PRECIOUS: $(daemon_TDIR)/%.o

# cdspd under the sanitizers (reads the variables above)
include daemon/sanitize.mk
