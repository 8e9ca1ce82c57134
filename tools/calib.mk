# cdsp_calib: checkerboard calibration (C++17, OpenCV) and its check.
#
# OpenCV comes from Debian's per-module packages (.ci/packages.d/calib.txt:
# calib3d, imgcodecs, imgproc, core), not the whole libopencv-dev, which
# pulls in VTK, Qt and the rest. Those packages ship no opencv4.pc (only
# libopencv-dev does), so the flags are Debian's paths unless pkg-config
# knows better. OpenCV's headers are system headers: our warnings only.

CALIB_CXX      ?= g++
CALIB_CV_INC   := $(patsubst -I%,-isystem %,$(shell pkg-config --cflags-only-I opencv4 2>/dev/null))
CALIB_CV_INC   := $(if $(CALIB_CV_INC),$(CALIB_CV_INC),-isystem /usr/include/opencv4)
CALIB_CV_LIBS  := -lopencv_calib3d -lopencv_imgcodecs -lopencv_imgproc -lopencv_core
# cairo draws the printable board (--print-board): PDF, SVG, PNG
CALIB_CAIRO_INC  := $(patsubst -I%,-isystem %,$(shell pkg-config --cflags-only-I cairo 2>/dev/null))
CALIB_CAIRO_LIBS := $(shell pkg-config --libs cairo 2>/dev/null || echo -lcairo)
# the camera_info YAML is the host library's writer: libcdsp_host and
# libcdsp (host/host.mk, the top Makefile), their headers and packages
CALIB_CXXFLAGS := -std=c++17 -Wall -Wextra -pedantic -Werror -Wshadow -Wpointer-arith \
                  -Wmissing-declarations $(OPT) -g -MMD -MP -Iinclude $(HOSTLIB_INC) \
                  $(CALIB_CV_INC) $(CALIB_CAIRO_INC)

CALIB_SRC := tools/cdsp_calib.cpp tools/calib_core.cpp tools/calib_output.cpp tools/calib_board.cpp
CALIB_OBJ := $(patsubst tools/%.cpp,$(BUILD)/calib/%.o,$(CALIB_SRC))

$(BUILD)/calib/%.o: tools/%.cpp
	@mkdir -p $(@D)
	$(CALIB_CXX) $(CALIB_CXXFLAGS) -c $< -o $@

$(BUILD)/cdsp_calib: $(CALIB_OBJ) $(CDSP_HOST_LIB) $(host_LIB)
	$(CALIB_CXX) $(CALIB_OBJ) $(CDSP_HOST_LIB) $(host_LIB) $(CALIB_CV_LIBS) $(CALIB_CAIRO_LIBS) \
	    $(HOSTLIB_PKG_LIBS) -lm -o $@

ALL_TARGETS += $(BUILD)/cdsp_calib

-include $(CALIB_OBJ:.o=.d)

# The check: synthetic boards rendered by tests/calib/board_render.c, the
# real binary run on them, its YAML read back with libyaml, then used by
# cdsp_tool solve on simulated pipes (tools/tool.mk builds cdsp_tool).
CALIB_TEST := $(BUILD)/calib/test_calib

$(CALIB_TEST): tests/calib/test_calib.c tests/calib/board_render.c tests/calib/board_render.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itests/calib tests/calib/test_calib.c tests/calib/board_render.c \
	  -lcmocka -lyaml -ljson-c -lm -o $@

.PHONY: check-calib
# Each run works in a directory of its own (kept when the check fails, to
# look at the images), so concurrent `make check` runs do not collide.
check-calib: $(BUILD)/cdsp_calib $(BUILD)/cdsp_tool $(CALIB_TEST)
	@work=$$(mktemp -d $(BUILD)/calib/work.XXXXXX) && \
	 $(RUN) "calib/test_calib" $(CALIB_TEST) $(BUILD)/cdsp_calib $(BUILD)/cdsp_tool $$work && \
	 rm -rf $$work

CHECK_STEPS += check-calib
