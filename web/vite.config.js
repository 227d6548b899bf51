// Builds the operator's page into the CMake build tree (hmi/CMakeLists.txt includes web/web.cmake,
// which passes EDM_WEB_OUT). uPlot is imported from node_modules and bundled, with its CSS, into
// the hashed files under assets/ (docs/web.md "How the page is built").
import { defineConfig } from 'vite';

export default defineConfig({
  base: './',
  build: {
    outDir: process.env.EDM_WEB_OUT || '../build/web',
    emptyOutDir: true,
    target: 'es2020',
    sourcemap: false,
    chunkSizeWarningLimit: 200,
  },
});
