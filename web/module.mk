# web/: `hexcnc web`, the operator's station (docs/ui.md): civetweb serves the page built
# from ui/ (npm + esbuild, ui/build.sh) and bridges WebSockets to the session's socket.
LIB_SRCS += web/web_config.c web/web_local.c web/web_preview.c web/web_server.c
UI_OUT := $(O)/share/hexcnc/ui
UI_FILES += $(UI_OUT)/index.html
$(UI_OUT)/index.html: $(wildcard ui/src/*) ui/package.json ui/package-lock.json ui/build.sh
	$(call say,UI,$(UI_OUT))
	$(Q)sh ui/build.sh $(UI_OUT)
# bin/hexcnc-web links without Ceres (web/web_main.c says why); `hexcnc web` runs it.
WEB_BIN := $(BINDIR)/hexcnc-web
EXTRA_BINS += $(WEB_BIN)
$(WEB_BIN): $(BUILD)/web/web_main.o $(LIBDIR)/libhexcnc.a
	@mkdir -p $(@D)
	$(call say,LINK,$@)
	$(Q)$(CC) $(LDFLAGS) $^ $(filter-out $(CERES_LIBS),$(LDLIBS)) -o $@
SCRIPT_TESTS += tests/e2e/web_station.sh
TESTS += test_web
