# hexcnc: top-level make front.
#
# Every build target first makes sure the Debian packages are there (mk/deps.sh is a fast
# no-op when they are), then runs the real build in mk/build.mk, which reads pkg-config.
#
#   make            build bin/ and lib/
#   make deps       install missing Debian packages
#   make test       build and run every test (unit, HAL-graph, G-code, end to end)
#   make sanitize   the same tests built with ASan + UBSan (in build/san/)
#   make bench      run the benchmarks
#   make calibration the simulated kinematic calibration (docs/calibration.md)
#   make run        run the simulated TMU hexapod on the paper's programs
#   make station    the simulated TMU hexapod as a running machine, its operator's station
#                   at http://127.0.0.1:8080/ (docs/ui.md); Ctrl-C ends it
#   make ini-doc    write docs/ini.md from the INI key table (common/config_keys.c)
#   make install PREFIX=/usr/local

PREFIX ?= /usr/local
BUILD_MAKE = $(MAKE) --no-print-directory -f mk/build.mk

.PHONY: all deps test sanitize bench run station experiment calibration install clean fuzz ini-doc
all: deps
	@$(BUILD_MAKE) all
deps:
	@sh mk/deps.sh
test: deps
	@$(BUILD_MAKE) test
sanitize: deps
	@$(BUILD_MAKE) O=build/san SAN=1 test
bench: deps
	@$(BUILD_MAKE) bench
run: deps
	@$(BUILD_MAKE) run
station: all
	scripts/hexcnc-start --realtime configs/sim/tmu-hexapod.ini
experiment: deps
	@$(BUILD_MAKE) experiment
calibration: deps
	@$(BUILD_MAKE) calibration
fuzz: deps
	@$(BUILD_MAKE) fuzz
ini-doc: deps
	@$(BUILD_MAKE) ini-doc
install: deps
	@$(BUILD_MAKE) install PREFIX=$(PREFIX)
clean:
	rm -rf build bin lib
