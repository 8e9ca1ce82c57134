# daemon/sanitize.mk: cdspd under the sanitizers, and the checks of issue 16
# that run it (docs/security.md, README "Operations"):
#   $(BUILD)/daemon-asan/cdspd  clang, AddressSanitizer + UndefinedBehavior-
#                               Sanitizer (libcdsp and libcdsp_host too);
#   $(BUILD)/daemon-tsan/cdspd  clang, ThreadSanitizer (libcdsp, libcdsp_host
#                               and the daemon instrumented; GLib and Aravis
#                               are not: tests/daemon/tsan.supp says what is
#                               suppressed there and why);
#   check-daemon-asan    faults.sh (sim and file sources) against the ASan
#                        build;
#   check-daemon-v4l2-asan  the vivid VM's GREY run against it;
#   check-daemon-aravis-asan / -tsan  aravis_e2e.sh against each;
#   check-daemon-valgrind  memcheck on the plain build: sim source, a few
#                        hundred frames, SIGTERM: no error, nothing leaked;
#   check-daemon-faults  tests/daemon/faults.sh on the plain build;
#   check-daemon-soak    tests/daemon/soak.sh for SOAK_CHECK_SECONDS (25);
#   check-daemon-security  tests/daemon/security.sh;
#   make soak            the soak for SOAK_SECONDS (600), not in make check.
# Included at the end of daemon/daemon.mk (it reads daemon_SRC, daemon_DEFS,
# daemon_PKGS); libcdsp_host's sanitizer twins come from host/host.mk.
# Names start with dsan_.

dsan_SRC := $(daemon_SRC) cdspd.c
dsan_SYS := $(HOSTLIB_INC) -Idaemon $(daemon_DEFS) $(call daemon_sys,$(daemon_PKGS))
dsan_CXX_WARN := -std=c++17 -Wall -Wextra -pedantic -Werror -Wshadow -MMD -MP -Iinclude
dsan_LINK := $(if $(daemon_CXX_SRC),$(CLANG)++,$(CLANG))

# dsan_variant NAME, SANITIZER FLAGS, libcdsp archive, libcdsp_host archive:
# the daemon's objects and binary in $(BUILD)/daemon-NAME.
define dsan_variant
dsan_$(1)_DIR := $(BUILD)/daemon-$(1)
dsan_$(1)_BIN := $$(dsan_$(1)_DIR)/cdspd
dsan_$(1)_OBJ := $$(patsubst %.c,$$(dsan_$(1)_DIR)/%.o,$$(dsan_SRC)) \
                 $$(patsubst %.cpp,$$(dsan_$(1)_DIR)/%.o,$$(daemon_CXX_SRC))

$$(dsan_$(1)_DIR)/%.o: daemon/%.c $$(daemon_STAMP)
	@mkdir -p $$(@D)
	$(CLANG) $$(BASE_CFLAGS) -O1 -g $(2) $$(dsan_SYS) -c $$< -o $$@

$$(dsan_$(1)_DIR)/%.o: daemon/%.cpp $$(daemon_STAMP)
	@mkdir -p $$(@D)
	$(CLANG)++ $$(dsan_CXX_WARN) -O1 -g $(2) $$(dsan_SYS) -c $$< -o $$@

$$(dsan_$(1)_BIN): $$(dsan_$(1)_OBJ) $(3) $(4)
	$$(dsan_LINK) $(2) $$(dsan_$(1)_OBJ) $(3) $(4) $$(daemon_LIBS) -o $$@

-include $$(dsan_$(1)_OBJ:.o=.d)
endef

$(eval $(call dsan_variant,asan,$(SAN_FLAGS),$(asan_LIB),$(HOSTLIB_ASAN_LIB)))

# ThreadSanitizer: libcdsp and libcdsp_host instrumented as well, so the
# frame buffers the capture thread fills and the processing thread reads
# are seen on both sides.
dsan_TSAN_FLAGS := -fsanitize=thread -fno-omit-frame-pointer
TSAN_CFLAGS := $(BASE_CFLAGS) -O1 -g $(dsan_TSAN_FLAGS)
$(eval $(call lib_variant,tsan,$(CLANG),TSAN_CFLAGS))
$(eval $(call dsan_variant,tsan,$(dsan_TSAN_FLAGS),$(tsan_LIB),$(HOSTLIB_TSAN_LIB)))

# The environment of a sanitized run. Findings are written to
# $$work/san.PID by every sanitized process (tests/daemon/lib.sh sets
# log_path and fails the script when such a file exists), and make the
# process exit with a status no test expects. LSan: GLib's and Aravis's
# one-time allocations (type system, main context) are not the daemon's.
dsan_ENV = CDSPD_SAN=1 CDSPD_WAIT_SCALE=4 \
  ASAN_OPTIONS=detect_leaks=1:exitcode=86:abort_on_error=0 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/daemon/lsan.supp:print_suppressions=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:exitcode=87 \
  TSAN_OPTIONS=halt_on_error=0:exitcode=66:second_deadlock_stack=1:suppressions=$(CURDIR)/tests/daemon/tsan.supp

dsan_E2E_DEPS := $(daemon_RX) $(daemon_TOOL) $(daemon_NOTIFY)
dsan_asan_ENV = $(dsan_ENV) CDSPD=$(dsan_asan_BIN) CDSPD_RX=$(daemon_RX) \
  CDSP_LISTEN="$(daemon_TOOL) listen" CDSPD_TMP=$(daemon_TDIR)/tmp NOTIFY_RX=$(daemon_NOTIFY)

.PHONY: check-daemon-asan check-daemon-valgrind check-daemon-faults check-daemon-soak \
        check-daemon-security soak
# Under ASan: faults.sh (the sim and file sources end to end: frames of
# mixed sizes, a receiver gone, the 100-reload storm, the recording
# directory, the firewall) and, below, aravis_e2e.sh (the fake GigE
# camera). Left out to keep make check's time: sim_e2e.sh (its first scenario renders 64
# frames of 640 x 480, a minute under ASan here, within bounds of its own
# the build would exceed; faults.sh runs the same sim and file paths),
# errors.sh (its configuration errors are the fuzz targets' ground,
# tests/fuzz) and the soak.
check-daemon-asan: $(dsan_asan_BIN) $(dsan_E2E_DEPS)
	@$(dsan_asan_ENV) $(RUN) "daemon-asan/faults" tests/daemon/faults.sh

# The vivid VM's GREY run (v4l2: corrupted buffer, packet loss, unplug and
# reopen) against the ASan build (vm_inner.sh configures vivid's nodes
# before cdspd can reopen them after the unplug, whatever its speed).
.PHONY: check-daemon-v4l2-asan
check-daemon-v4l2-asan: $(dsan_asan_BIN) $(daemon_RX) $(daemon_FEED)
	@CDSPD_TMP=$(daemon_TDIR)/tmp VM_RUNS="GREY-loss" $(RUN) "daemon-asan/v4l2-vivid-vm" \
	    tests/daemon/vm_v4l2.sh $(dsan_asan_BIN) $(daemon_RX) $(daemon_FEED)

check-daemon-valgrind: $(daemon_BIN) $(daemon_RX)
	@$(daemon_ENV) $(RUN) "daemon/valgrind" tests/daemon/valgrind.sh

# faults.sh's camera section needs the fake GigE camera (aravis source)
dsan_FAULTS_CAM := $(if $(filter -DCDSPD_HAVE_ARAVIS,$(daemon_DEFS)),$(BUILD)/fakecam/cdsp_fakecam)
check-daemon-faults: $(daemon_BIN) $(daemon_RX) $(daemon_TDIR)/clockshim.so $(dsan_FAULTS_CAM)
	@$(daemon_ENV) CLOCKSHIM=$(daemon_TDIR)/clockshim.so $(RUN) "daemon/faults" tests/daemon/faults.sh \
	    $(dsan_FAULTS_CAM)

# the clock shim (LD_PRELOAD) of faults.sh: CLOCK_REALTIME stepped
$(daemon_TDIR)/clockshim.so: tests/daemon/clockshim.c
	@mkdir -p $(@D)
	$(CC) $(filter-out -MMD -MP,$(HOST_CFLAGS)) -fPIC -shared $< -ldl -o $@

SOAK_SECONDS ?= 600
SOAK_CHECK_SECONDS ?= 25
check-daemon-soak: $(daemon_BIN) $(daemon_RX) $(daemon_MAVRX)
	@$(daemon_ENV) MAVLINK_RX=$(daemon_MAVRX) SOAK_SECONDS=$(SOAK_CHECK_SECONDS) $(RUN) "daemon/soak" \
	    tests/daemon/soak.sh
soak: $(daemon_BIN) $(daemon_RX) $(daemon_MAVRX)
	@$(daemon_ENV) MAVLINK_RX=$(daemon_MAVRX) SOAK_SECONDS=$(SOAK_SECONDS) tests/daemon/soak.sh

check-daemon-security: $(daemon_BIN) $(daemon_RX)
	@$(daemon_ENV) $(RUN) "daemon/security" tests/daemon/security.sh

dsan_CHECKS := check-daemon-asan check-daemon-valgrind check-daemon-faults check-daemon-soak \
               check-daemon-security
ifneq ($(filter -DCDSPD_HAVE_V4L2,$(daemon_DEFS)),)
dsan_CHECKS += check-daemon-v4l2-asan
endif

ifneq ($(filter -DCDSPD_HAVE_ARAVIS,$(daemon_DEFS)),)
.PHONY: check-daemon-aravis-asan check-daemon-aravis-tsan
dsan_FAKECAM := $(BUILD)/fakecam/cdsp_fakecam
check-daemon-aravis-asan: $(dsan_asan_BIN) $(daemon_RX) $(dsan_FAKECAM)
	@$(dsan_asan_ENV) $(RUN) "daemon-asan/aravis-fakecam" tests/daemon/aravis_e2e.sh $(dsan_FAKECAM)
check-daemon-aravis-tsan: $(dsan_tsan_BIN) $(daemon_RX) $(dsan_FAKECAM)
	@$(dsan_ENV) CDSPD=$(dsan_tsan_BIN) CDSPD_RX=$(daemon_RX) CDSPD_TMP=$(daemon_TDIR)/tmp \
	    $(RUN) "daemon-tsan/aravis-fakecam" tests/daemon/aravis_e2e.sh $(dsan_FAKECAM)
dsan_CHECKS += check-daemon-aravis-asan check-daemon-aravis-tsan
endif
# the fake GigE camera's (one per machine): the Makefile's gvcp lane;
# faults.sh's section 7 runs it on the plain build
CHECK_LANE_gvcp += check-daemon-faults $(filter check-daemon-aravis-%,$(dsan_CHECKS))

CHECK_STEPS += $(dsan_CHECKS)
