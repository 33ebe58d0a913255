// Texel Studio front end build. The engine serves the output directory
// (`texel studio --web DIR`); TEXEL_WEB_OUT picks it (default ../build/web,
// next to the C++ build), so parallel builds never share one output.
// TEXEL_TEST_HOOKS=1 (npm run build:test) makes the test build, the only one
// with the browser tests' hooks (src/env.d.ts); `npm run build` has none.
import { defineConfig } from 'vite';

const outDir = process.env.TEXEL_WEB_OUT ?? '../build/web';

export default defineConfig({
  base: './',
  define: { __TEXEL_TEST_HOOKS__: JSON.stringify(process.env.TEXEL_TEST_HOOKS === '1') },
  build: {
    outDir,
    emptyOutDir: true,
    target: 'es2022',
    sourcemap: false,
    chunkSizeWarningLimit: 400,
  },
  server: {
    // `npm run dev` against a running `texel studio --port 8080`.
    proxy: { '/ws': { target: 'ws://127.0.0.1:8080', ws: true } },
  },
});
