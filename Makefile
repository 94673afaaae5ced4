# skycast: the two commands a new user runs are `make demo` and `make test`.
# Both install Mesa's software Vulkan driver (lavapipe) first when it is missing, so they work on
# a fresh Debian machine with no GPU.

SHELL := /bin/bash
VULKAN_PACKAGES := mesa-vulkan-drivers libvulkan1
# Mesa's Vulkan loader complains on every start when this is unset; /tmp silences it.
export XDG_RUNTIME_DIR ?= /tmp

.PHONY: demo test vulkan fuzz

demo: vulkan
	cargo run --release --quiet -- demo

test: vulkan
	cargo fmt --check
	cargo clippy --all-targets -- -D warnings
	cargo test --all-targets
	cargo test --doc

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
