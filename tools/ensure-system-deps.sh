#!/usr/bin/env bash
# System packages `make setup` cannot install with pip or npm (DESIGN.md, "Real components"):
#   venv  [python]       : the interpreter can create a venv (Debian splits ensurepip into python3-venv);
#   runtime [venv-python]: Chromium for the WebGPU lab (Debian's /usr/bin/chromium, or Playwright's
#                          download) and Mesa lavapipe (Vulkan ICD) for wgpu-py compute on the CPU.
# As root (or with password-less sudo) on Debian/Ubuntu it apt-installs what is missing; otherwise
# it falls back to Playwright's Chromium, or stops and says what to install.
set -euo pipefail

MODE="${1:-runtime}"
LVP_GLOB="/usr/share/vulkan/icd.d/lvp_icd*.json"

SUDO=()
CAN_APT=0
if command -v apt-get >/dev/null 2>&1; then
    if [[ "$(id -u)" -eq 0 ]]; then
        CAN_APT=1
    elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        SUDO=(sudo -n)
        CAN_APT=1
    fi
fi

apt_install() {
    echo "==> apt-get update && apt-get install $*"
    "${SUDO[@]}" apt-get update
    "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "$@"
}

ensure_venv() {
    local python="${1:-python3}"
    "${python}" -c 'import ensurepip, venv' 2>/dev/null && return 0
    if [[ "${CAN_APT}" -eq 1 ]]; then
        apt_install python3-venv
        "${python}" -c 'import ensurepip, venv' && return 0
    fi
    echo "error: ${python} cannot create virtual environments (no ensurepip). Install it, e.g.:" >&2
    echo "    sudo apt-get install python3-venv" >&2
    exit 1
}

have_chromium() {
    if [[ -n "${CREATUREGEN_CHROMIUM:-}" ]]; then
        [[ -x "${CREATUREGEN_CHROMIUM}" ]] && return 0
        echo "error: CREATUREGEN_CHROMIUM=${CREATUREGEN_CHROMIUM} is not an executable file" >&2
        exit 1
    fi
    [[ -x /usr/bin/chromium ]]
}

have_lavapipe() {
    compgen -G "${LVP_GLOB}" >/dev/null
}

ensure_runtime() {
    local venv_python="${1:-.venv/bin/python}"
    if have_chromium && have_lavapipe; then
        echo "==> system deps present (chromium, lavapipe)"
        return 0
    fi
    if [[ "${CAN_APT}" -eq 1 ]]; then
        apt_install chromium mesa-vulkan-drivers
        have_chromium || { echo "error: apt-get finished but /usr/bin/chromium is missing" >&2; exit 1; }
        have_lavapipe || { echo "error: apt-get finished but no ${LVP_GLOB} exists" >&2; exit 1; }
        echo "==> system deps installed (chromium, lavapipe)"
        return 0
    fi
    # No root: Playwright can still fetch its own Chromium into the user's cache.
    if ! have_chromium; then
        echo "==> no /usr/bin/chromium and no root: installing Playwright's Chromium instead"
        if ! "${venv_python}" -m playwright install chromium; then
            echo "error: could not install Chromium. Install it yourself, e.g.:" >&2
            echo "    sudo apt-get install --no-install-recommends chromium" >&2
            echo "or set CREATUREGEN_CHROMIUM=/path/to/chromium" >&2
            exit 1
        fi
    fi
    if ! have_lavapipe; then
        echo "error: Mesa lavapipe (the Vulkan CPU driver wgpu-py runs on) is missing: no ${LVP_GLOB}." >&2
        echo "Install it, e.g.:" >&2
        echo "    sudo apt-get install --no-install-recommends mesa-vulkan-drivers" >&2
        exit 1
    fi
    echo "==> system deps present (Playwright's chromium, lavapipe)"
}

case "${MODE}" in
    venv) ensure_venv "${2:-python3}" ;;
    runtime) ensure_runtime "${2:-.venv/bin/python}" ;;
    *)
        echo "usage: $0 venv [python] | runtime [venv-python]" >&2
        exit 2
        ;;
esac
