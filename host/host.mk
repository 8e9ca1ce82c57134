# host/host.mk: libcdsp_host, the host library between libcdsp and the
# programs (frame files, camera_info YAML, JSON records and their field
# list, the wire protocol's encoder and decoder, ground truth), used by
# cdsp_tool (tools/), cdspd (daemon/) and the tests. It includes nothing
# of tools/ or daemon/.
#
# Built here, and only here, in every variant the others link:
#   $(CDSP_HOST_LIB)       build/libcdsp_host.a, the host build ($(CC))
#   $(HOSTLIB_ASAN_LIB)    clang, ASan/UBSan (cdsp_tool's and cdspd's ASan builds)
#   $(HOSTLIB_TSAN_LIB)    clang, TSan (cdspd's TSan build)
#   $(HOSTLIB_FUZZ_LIB)    clang, ASan/UBSan + libFuzzer coverage (tests/fuzz)
# Included by the top-level Makefile before every other fragment; names
# start with hostlib_ / HOSTLIB_ (host_ is libcdsp's host variant).

# The libraries libcdsp_host itself uses: the one list. A program adds its
# own (cdsp_tool: cairo, fontconfig; cdspd: its camera sources).
HOSTLIB_PKGS := yaml-0.1 spng json-c libjpeg libtiff-4
HOSTLIB_PKG_FALLBACK := -lyaml -lspng -ljson-c -ljpeg -ltiff
# their headers as system headers (our warnings only)
HOSTLIB_PKG_CFLAGS := $(patsubst -I%,-isystem %,$(shell pkg-config --cflags $(HOSTLIB_PKGS) 2>/dev/null))
HOSTLIB_PKG_LIBS := $(shell pkg-config --libs $(HOSTLIB_PKGS) 2>/dev/null || echo $(HOSTLIB_PKG_FALLBACK))
# what a part that uses libcdsp_host compiles with
HOSTLIB_INC := -Ihost

hostlib_SRC := $(sort $(wildcard host/*.c))

# hostlib_variant NAME, compiler, flags: objects in $(BUILD)/hostlib-NAME,
# the archive $(BUILD)/hostlib-NAME/libcdsp_host.a
define hostlib_variant
hostlib_$(1)_DIR := $(BUILD)/hostlib-$(1)
hostlib_$(1)_OBJ := $$(patsubst host/%.c,$$(hostlib_$(1)_DIR)/%.o,$$(hostlib_SRC))
hostlib_$(1)_LIB := $$(hostlib_$(1)_DIR)/libcdsp_host.a

$$(hostlib_$(1)_DIR)/%.o: host/%.c
	@mkdir -p $$(@D)
	$(2) $(3) $$(HOSTLIB_INC) $$(HOSTLIB_PKG_CFLAGS) -c $$< -o $$@

$$(hostlib_$(1)_LIB): $$(hostlib_$(1)_OBJ)
	@mkdir -p $$(@D)
	rm -f $$@ && $(AR) rcs $$@ $$^

-include $$(hostlib_$(1)_OBJ:.o=.d)
endef

$(eval $(call hostlib_variant,plain,$(CC),$(HOST_CFLAGS)))
$(eval $(call hostlib_variant,asan,$(CLANG),$(ASAN_CFLAGS)))
$(eval $(call hostlib_variant,tsan,$(CLANG),$(BASE_CFLAGS) -O1 -g -fsanitize=thread -fno-omit-frame-pointer))
$(eval $(call hostlib_variant,fuzz,$(CLANG),$(BASE_CFLAGS) -O1 $(SAN_FLAGS) -fsanitize=fuzzer-no-link))

# The library programs link: build/libcdsp_host.a.
CDSP_HOST_LIB := $(BUILD)/libcdsp_host.a
$(CDSP_HOST_LIB): $(hostlib_plain_LIB)
	cp $< $@
HOSTLIB_ASAN_LIB := $(hostlib_asan_LIB)
HOSTLIB_TSAN_LIB := $(hostlib_tsan_LIB)
HOSTLIB_FUZZ_LIB := $(hostlib_fuzz_LIB)

ALL_TARGETS += $(CDSP_HOST_LIB)
