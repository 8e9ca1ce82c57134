# tests/mutants/mutants.mk: `make mutants`, the mutation score of the test
# suites (not part of `make check`). tests/mutants/run.sh copies the tree
# once into $(BUILD)/mutants/base and builds it there, then for each row of
# tests/mutants/mutants.txt copies that base, applies the row's one
# substitution and rebuilds only what it changed (the lib tests are linked
# from objects, so a lib/ mutant recompiles one file and relinks).
# Variables and targets start with mut_ / mutant.

# The lib suites as separate objects + links (the check rules compile and
# link each test in one step, which would recompile all of them per mutant).
#   $(1) variant (host, float), $(2) compiler, $(3) flags variable name
define mut_variant
mut_$(1)_TESTS := $$(patsubst tests/lib/%.c,$$($(1)_DIR)/mtests/%,$$(LIB_TEST))
$$($(1)_DIR)/mtests/%.o: tests/lib/%.c
	@mkdir -p $$(@D)
	$(2) $$($(3)) -Itests/lib -c $$< -o $$@
$$(mut_$(1)_TESTS): $$($(1)_DIR)/mtests/%: $$($(1)_DIR)/mtests/%.o $$($(1)_DIR)/tests/support.o $$($(1)_LIB)
	$(2) $$($(3)) $$^ -lcmocka -lm -o $$@
-include $$(mut_$(1)_TESTS:=.d)
endef
$(eval $(call mut_variant,host,$(CC),HOST_CFLAGS))
$(eval $(call mut_variant,float,$(CC),FLOAT_CFLAGS))

.PHONY: mutants mutant-lib-host mutant-lib-float mutant-tool mutant-hostunit mutant-daemon
mutant-lib-host: $(mut_host_TESTS)
mutant-lib-float: $(mut_float_TESTS)
# (tools/tool.mk is read after this file: its names expand at run time)
mutant-tool:
	@$(MAKE) --no-print-directory $(tool_BIN) $(tool_E2E)
# the host library's unit suites (tests/tool/test_host_*) and the daemon's
mutant-hostunit:
	@$(MAKE) --no-print-directory $(tool_UNIT)
mutant-daemon:
	@$(MAKE) --no-print-directory $(daemon_UNIT)

# MUTANTS=id1,id2 runs only those rows.
mutants:
	@nice tests/mutants/run.sh $(BUILD)/mutants tests/mutants/mutants.txt $(MUTANTS)
