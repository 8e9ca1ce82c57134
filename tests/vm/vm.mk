# tests/vm/vm.mk: V4L2 without hardware - the kernel's vivid driver in a qemu
# VM (tests/vm/run-in-vm.sh, docs/testing-hardware.md). check-vm-v4l2 boots
# Debian's current kernel (downloaded once into $(BUILD)/vm/cache) and checks
# that frames written to vivid's output node come back pixel-exact from its
# capture node through libv4l2.

vm_DIR      := $(BUILD)/vm
vm_LOOP     := $(vm_DIR)/v4l2_loop
vm_V4L2_LIBS = $(shell pkg-config --libs libv4l2 2>/dev/null || echo -lv4l2)
# Hard limit on one VM run: a boot takes about 5 s under TCG here, the loop
# test 2 s (70 s seen at a load of 20 on 2 cores); a hang bound, not a speed
# requirement: a loaded machine only waits longer.
vm_TIMEOUT  ?= 1200

# (libcdsp_host for its clock only: nothing that needs another library)
$(vm_LOOP): tests/vm/v4l2_loop.c $(CDSP_HOST_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(HOSTLIB_INC) $< $(CDSP_HOST_LIB) $(vm_V4L2_LIBS) -o $@

-include $(vm_LOOP).d

.PHONY: check-vm-v4l2
check-vm-v4l2: $(vm_LOOP)
	@$(RUN) "vm/v4l2-loop" tests/vm/run-in-vm.sh --timeout $(vm_TIMEOUT) \
	    --file $(vm_LOOP):/bin/v4l2_loop -- v4l2_loop

ALL_TARGETS += $(vm_LOOP)
CHECK_STEPS += check-vm-v4l2
