# tests/fakecam/fakecam.mk: a GigE Vision camera without hardware
# (docs/testing-hardware.md). cdsp_fakecam serves frames drawn by libcdsp's
# renderer through libaravis's fake-camera API on 127.0.0.1; arv_probe, an
# Aravis client, checks them pixel for pixel; fakecam_path.h gives every
# frame's ground truth to any receiver (the daemon's end-to-end test).

fakecam_DIR  := $(BUILD)/fakecam
fakecam_BINS := $(fakecam_DIR)/cdsp_fakecam $(fakecam_DIR)/arv_probe
# GLib's and Aravis's headers are not -pedantic clean: include them as
# system headers so the project's warnings apply to our code only.
fakecam_ARV_CFLAGS = $(patsubst -I%,-isystem %,$(shell pkg-config --cflags aravis-0.8 2>/dev/null))
fakecam_ARV_LIBS   = $(shell pkg-config --libs aravis-0.8 2>/dev/null || echo -laravis-0.8)

$(fakecam_BINS): $(fakecam_DIR)/%: tests/fakecam/%.c tests/fakecam/cli.c tests/fakecam/cli.h \
                 tests/fakecam/fakecam_path.h $(CDSP_HOST_LIB) $(host_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(HOSTLIB_INC) $(fakecam_ARV_CFLAGS) -Itests/fakecam $< tests/fakecam/cli.c \
	    $(CDSP_HOST_LIB) $(host_LIB) $(fakecam_ARV_LIBS) -lm -o $@

-include $(fakecam_BINS:=.d)

.PHONY: check-fakecam
check-fakecam: $(fakecam_BINS)
	@$(RUN) "fakecam/gige-loopback" tests/fakecam/check.sh $(fakecam_BINS)

ALL_TARGETS += $(fakecam_BINS)
CHECK_STEPS += check-fakecam
# one fake camera per machine (GVCP's fixed port): the Makefile's gvcp lane
CHECK_LANE_gvcp += check-fakecam
