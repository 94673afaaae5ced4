# skycast: the two commands a new user runs are `make demo` and `make test`.
# Both install Mesa's software Vulkan driver (lavapipe) first when it is missing, so they work on
# a fresh Debian machine with no GPU.

SHELL := /bin/bash
VULKAN_PACKAGES := mesa-vulkan-drivers libvulkan1
# Mesa's Vulkan loader complains on every start when this is unset; /tmp silences it.
export XDG_RUNTIME_DIR ?= /tmp

.PHONY: demo test vulkan fuzz soak

demo: vulkan
	cargo run --release --quiet -- demo

test: vulkan
	cargo fmt --check
	cargo clippy --all-targets -- -D warnings
	cargo test --all-targets
	cargo test --doc

# The live-weather soak test (ignored by default): one simulated hour, a weather change every
# five minutes; fails if memory (RSS) or the renderer's GPU buffers grow after the first changes.
soak: vulkan
	cargo test --test live -- --ignored --nocapture

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
