// Vite's dev server pre-bundles dependencies into node_modules/.vite/deps, away from their assets, so
// a package's `new URL('../assets/…', import.meta.url)` would miss there (vitejs/vite#8427): the packages'
// READMEs ask for this one setting, and tests/test_consumer.py writes the real package names into it.
export default { optimizeDeps: { exclude: [] } };
