/// <reference types="vite/client" />

/**
 * True only in the test build (`npm run build:test`, vite.config.ts): the
 * page then records counters and latencies in window.__texelStats for the
 * browser tests. The production bundle has neither (tests/build).
 */
declare const __TEXEL_TEST_HOOKS__: boolean;
