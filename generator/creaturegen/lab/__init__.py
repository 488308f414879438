"""The lab side of creaturegen: serve web_lab/ and drive it in headless Chromium (WebGPU on SwiftShader).

GPU numbers reach Python only through this package: the page publishes ``window.__lab`` telemetry
after reading buffers back from the GPU, and the harness returns that object as plain JSON data.

Import the submodules directly (``creaturegen.lab.server``, ``creaturegen.lab.browser``): nothing is
re-exported here, so ``python -m creaturegen.lab.server`` runs cleanly and serving files never
imports Playwright.
"""
