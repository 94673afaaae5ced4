# skycast: the two commands a new user runs are `make demo` and `make test`.
# Both install Mesa's software Vulkan driver (lavapipe) first when it is missing, so they work on
# a fresh Debian machine with no GPU; `make test` also installs Xvfb, the X server without a
# screen that `skycast view`'s window test runs in.

SHELL := /bin/bash
VULKAN_PACKAGES := mesa-vulkan-drivers libvulkan1
# Xvfb, and the X client libraries winit loads at run time (nothing is linked at build time).
XVFB_PACKAGES := xvfb xauth libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0
# Mesa's Vulkan loader complains on every start when this is unset; /tmp silences it.
export XDG_RUNTIME_DIR ?= /tmp

.PHONY: demo test vulkan xvfb fuzz soak pictures mutants docs

demo: vulkan
	cargo run --release --quiet -- demo

test: vulkan xvfb
	cargo fmt --check
	cargo clippy --all-targets -- -D warnings
	cargo test --all-targets
	cargo test --doc
	RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet
	# A simulator embedding the library compiles none of the command line's crates.
	cargo clippy --lib --no-default-features -- -D warnings
	! cargo tree -e normal --no-default-features | grep -E '^[^a-z]*(clap|indicatif|env_logger|anyhow|exr|winit|noto-sans-mono-bitmap) '
	# The crate as published stays under crates.io's 10 MB (Cargo.toml's `exclude`).
	@bytes=$$(cargo package --list --allow-dirty --quiet | while read -r f; do [ -f "$$f" ] && stat -c %s "$$f"; done | awk '{ s += $$1 } END { print s + 0 }'); \
	echo "cargo package: $$bytes bytes of files"; \
	[ "$$bytes" -gt 0 ] && [ "$$bytes" -lt 10000000 ] || { echo "the package is over 10 MB: exclude more in Cargo.toml"; exit 1; }

# Hours of flight (tests/soak.rs; `make test` flies one): SOAK_HOURS simulated hours, a watched
# weather file rewritten every five minutes through six weathers (clear to thunderstorm cells),
# the figures of each hour printed; fails if a cycle of the weathers holds more GPU memory than
# the one before, or RSS grows by 2% from the first hour to the last. Release: about 5 s an hour.
SOAK_HOURS ?= 6
soak: vulkan
	SOAK_HOURS=$(SOAK_HOURS) cargo test --release --test soak -- --ignored --nocapture

# Regenerates the pictures of the README and the book (docs/src/pictures/): one block of each
# type (CPU), each theme over Orlando at 2 pm local, and frames along the three shipped flights
# (lavapipe is enough; ~1 minute).
SKYCAST := cargo run --quiet --
# The book shows the pictures and mdBook publishes only docs/src, so they live there.
PICTURES := docs/src/pictures
METARS := weather/awc-metars-2025-01-27T22Z.cache.csv
THEME = $(SKYCAST) render --at 28.5,-81.45 --time 2025-01-27T19:00:00Z --size 480x270
FRAME = $(SKYCAST) render --size 640x360
# The two shading models side by side (the book's Rendering, "Two shading models").
SHADING = $(SKYCAST) render --weather weather/themes/fair_weather_cumulus.toml --at 28.5,-81.45 --size 480x270
pictures: vulkan
	$(SKYCAST) sheet --out /tmp/skycast-sheet.png --over-sky $(PICTURES)/sheet_over_sky.png
	$(SKYCAST) preview --type cumulus_mediocris --lifecycle --out $(PICTURES)/lifecycle.png
	$(SKYCAST) preview --all --out $(PICTURES)/types/
	$(THEME) --weather weather/themes/fair_weather_cumulus.toml --alt-ft 2500 --heading 90 --pitch 6 --out $(PICTURES)/themes/fair_weather_cumulus.png
	$(THEME) --weather weather/themes/building_cumulus_cb_line.toml --alt-ft 3000 --heading 90 --pitch 8 --out $(PICTURES)/themes/building_cumulus_cb_line.png
	$(THEME) --weather weather/themes/low_stratus_and_fog.toml --alt-ft 2600 --heading 90 --pitch -8 --out $(PICTURES)/themes/low_stratus_and_fog.png
	$(THEME) --weather weather/themes/frontal_nimbostratus.toml --alt-ft 900 --heading 90 --pitch 8 --out $(PICTURES)/themes/frontal_nimbostratus.png
	$(THEME) --weather weather/themes/thunderstorm_cells.toml --alt-ft 1500 --heading 90 --pitch 3 --out $(PICTURES)/themes/thunderstorm_cells.png
	$(THEME) --weather weather/themes/high_cirrus.toml --alt-ft 5000 --heading 205 --pitch 20 --out $(PICTURES)/themes/high_cirrus.png
	$(FRAME) --weather $(METARS) --at 33.90,-118.36 --alt-ft 3000 --heading 135 --pitch 8 --out $(PICTURES)/frames/cruise_under_cumulus.png
	$(FRAME) --weather $(METARS) --at 33.90,-118.36 --alt-ft 5500 --heading 135 --pitch -8 --out $(PICTURES)/frames/cruise_over_cumulus.png
	$(FRAME) --weather weather/themes/building_cumulus_cb_line.toml --at 28.5,-81.62 --alt-ft 3000 --heading 90 --pitch 10 --out $(PICTURES)/frames/cumulonimbus_line.png
	$(FRAME) --weather $(METARS) --at 29.4270,-98.6080 --alt-ft 5000 --heading 40 --pitch -3 --out $(PICTURES)/frames/approach_above_deck.png
	$(FRAME) --weather $(METARS) --at 29.4800,-98.5480 --alt-ft 3300 --heading 40 --pitch -3 --out $(PICTURES)/frames/approach_in_deck.png
	$(FRAME) --weather $(METARS) --at 29.5230,-98.5000 --alt-ft 1500 --heading 40 --pitch 10 --out $(PICTURES)/frames/approach_below_deck.png
	$(FRAME) --weather $(METARS) --at 53.43,-6.10 --time 2025-01-27T14:00:00Z --alt-ft 700 --heading 280 --pitch 12 --out $(PICTURES)/airports/dublin_approach.png
	$(FRAME) --weather $(METARS) --at -4.80,136.887 --alt-ft 900 --heading 0 --pitch 14 --out $(PICTURES)/airports/timika_cb.png
	$(FRAME) --weather weather/themes/low_stratus_and_fog.toml --at 28.5,-81.45 --time 2025-01-27T13:30:00Z --alt-ft 450 --heading 90 --pitch -4 --out $(PICTURES)/airports/fog_morning.png
	$(FRAME) --weather weather/views/low_overcast_heathrow.metar --at 51.4775,-0.4614 --time 2025-01-27T12:00:00Z --alt-ft 283 --heading 315 --pitch 10 --out $(PICTURES)/pilot/deck_below.png
	$(FRAME) --weather weather/views/low_overcast_heathrow.metar --at 51.4775,-0.4614 --time 2025-01-27T12:00:00Z --alt-ft 3083 --heading 135 --pitch -10 --out $(PICTURES)/pilot/deck_above.png
	$(FRAME) --weather weather/views/low_overcast_heathrow.metar --at 51.4775,-0.4614 --time 2025-01-27T12:00:00Z --alt-ft 4000 --heading 10 --pitch -89 --out $(PICTURES)/pilot/deck_nadir.png
	$(FRAME) --weather weather/views/high_broken_heathrow.metar --at 51.4775,-0.4614 --time 2025-01-27T12:00:00Z --alt-ft 1000 --heading 0 --pitch 45 --out $(PICTURES)/pilot/cirrocumulus_below.png
	$(FRAME) --weather weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2 --at 45,-35 --time 2011-01-15T14:30:00Z --alt-ft 35000 --heading 10 --pitch -5 --out $(PICTURES)/model/fl350_mid_atlantic.png
	cargo test --quiet --test pilot rain_falls_out_of_a_storm && cp target/tmp/pilot/storm/rain.png $(PICTURES)/pilot/storm_20km.png
	for m in wang harris_lastra; do \
		$(SHADING) --shading $$m --time 2025-01-27T19:00:00Z --alt-ft 2500 --heading 90 --pitch 6 --out $(PICTURES)/shading/noon_$$m.png && \
		$(SHADING) --shading $$m --time 2025-01-27T22:30:00Z --alt-ft 4500 --heading 246 --pitch 3 --out $(PICTURES)/shading/low_sun_$$m.png && \
		$(SHADING) --shading $$m --time 2025-01-27T22:52:00Z --alt-ft 3000 --heading 150 --pitch 5 --out $(PICTURES)/shading/dusk_$$m.png || exit 1; \
	done

# Builds the book (docs/book.toml, docs/src/) into docs/book/ with mdBook, installed when missing
# (`cargo install` compiles it: half an hour on the shared 2-core VM under load; the build itself
# takes under a second). `make test` does not need it: the
# book's links, pictures and quoted commands are checked by tests/docs.rs.
docs:
	@command -v mdbook >/dev/null || { echo "installing mdbook: cargo install --locked mdbook"; cargo install --locked mdbook; }
	mdbook build docs

# Runs every cargo-fuzz target for FUZZ_SECONDS each (see fuzz/README.md); needs cargo-fuzz.
FUZZ_SECONDS ?= 120
fuzz:
	@command -v cargo-fuzz >/dev/null || { echo "make fuzz needs cargo-fuzz: cargo install cargo-fuzz"; exit 1; }
	cd fuzz && for target in $$(RUSTC_BOOTSTRAP=1 cargo fuzz list); do \
		mkdir -p corpus/$$target; \
		seeds=$$([ -d seeds/$$target ] && echo seeds/$$target); \
		dict=$$([ -f dicts/$$target.dict ] && echo -dict=dicts/$$target.dict); \
		RUSTC_BOOTSTRAP=1 cargo fuzz run $$target --sanitizer none corpus/$$target $$seeds -- \
			$$dict -max_total_time=$(FUZZ_SECONDS) || exit 1; \
	done

# Mutation testing of the library's CPU stages (cargo-mutants, installed when missing): each
# mutant (an operator flipped, a function body replaced by a default value) is built and the unit
# tests run against it; one they do not catch is behaviour no unit test pins. In place, so it
# reuses target/ (a copy would rebuild every dependency); each file is put back after its mutants,
# so do not edit the tree while it runs. About 9 s a mutant on 2 cores (the default set: 184
# mutants, 27 minutes). MUTANTS_FILES picks the files (the default is the set scored in the
# book, docs/src/testing.md), MUTANTS_ARGS adds options (--shard 1/4, --list, --iterate to try again only what was
# not caught). Results in mutants.out/ (caught.txt, missed.txt, unviable.txt, timeout.txt); missed
# mutants (cargo-mutants' status 2) are listed, not failed on: docs/src/testing.md says which are
# accepted and why.
MUTANTS_FILES ?= src/clouds/lifecycle.rs src/render/sprites/slots.rs src/weather/metar/sky.rs \
	src/shading/directional.rs
mutants:
	@command -v cargo-mutants >/dev/null || { echo "installing cargo-mutants"; cargo install --locked cargo-mutants; }
	cargo mutants --in-place --cargo-arg=--lib --timeout 30 --build-timeout 600 \
		$(addprefix --file ,$(MUTANTS_FILES)) $(MUTANTS_ARGS) || [ $$? = 2 ]
	@echo "missed (docs/src/testing.md lists the accepted ones, with why):"; cat mutants.out/missed.txt

# Installs lavapipe where missing: as root directly, else with sudo, else says the one line to run.
vulkan:
	@if ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 && /sbin/ldconfig -p | grep -q 'libvulkan.so.1 '; then \
		exit 0; \
	elif [ "$$(id -u)" = 0 ]; then \
		echo "installing the software Vulkan driver: apt-get install $(VULKAN_PACKAGES)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $(VULKAN_PACKAGES) >/dev/null; \
	elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then \
		echo "installing the software Vulkan driver: sudo apt-get install $(VULKAN_PACKAGES)"; \
		sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $(VULKAN_PACKAGES) >/dev/null; \
	else \
		echo "skycast renders through Mesa's software Vulkan driver; install it with:"; \
		echo "  sudo apt-get install -y --no-install-recommends $(VULKAN_PACKAGES)"; \
		exit 1; \
	fi

# Installs Xvfb where missing, the same way (tests/view.rs opens `skycast view`'s window in it).
xvfb:
	@if command -v Xvfb >/dev/null && command -v xauth >/dev/null && \
		/sbin/ldconfig -p | grep -q 'libxkbcommon-x11.so.0 ' && /sbin/ldconfig -p | grep -q 'libXcursor.so.1 '; then \
		exit 0; \
	elif [ "$$(id -u)" = 0 ]; then \
		echo "installing the virtual X server: apt-get install $(XVFB_PACKAGES)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $(XVFB_PACKAGES) >/dev/null; \
	elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then \
		echo "installing the virtual X server: sudo apt-get install $(XVFB_PACKAGES)"; \
		sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $(XVFB_PACKAGES) >/dev/null; \
	else \
		echo "the window test of skycast view runs in Xvfb; install it with:"; \
		echo "  sudo apt-get install -y --no-install-recommends $(XVFB_PACKAGES)"; \
		exit 1; \
	fi
