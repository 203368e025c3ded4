// Vite build of the dashboard into dist/ (index.html + hashed assets), served by `synbench serve`.
// `npm run dev` / `npm run preview` proxy /api and /ws to a running daemon (SYNBENCH_URL, default
// http://127.0.0.1:8080) so the page stays same-origin; the e2e test uses the preview proxy only
// when the daemon it starts does not serve web/dist itself.
import { defineConfig } from 'vite';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { gzipSync, constants } from 'node:zlib';

// Writes "X.gz" beside every text file of the build (best compression, once at build time; the
// html included, hence after the bundle is written): the daemon sends it to a browser that accepts
// gzip, so the first load moves about a third of the bytes.
function gzipAssets() {
  return {
    name: 'synbench-gzip-assets',
    apply: 'build',
    writeBundle(options, bundle) {
      for (const name of Object.keys(bundle)) {
        if (!/\.(js|css|html|svg|json)$/.test(name)) continue;
        const file = path.join(options.dir, name);
        writeFileSync(`${file}.gz`, gzipSync(readFileSync(file), { level: constants.Z_BEST_COMPRESSION }));
      }
    },
  };
}

const target = process.env.SYNBENCH_URL || 'http://127.0.0.1:8080';
const proxy = {
  '/api': { target, changeOrigin: true },
  '/metrics': { target, changeOrigin: true },
  '/ws': { target: target.replace(/^http/, 'ws'), ws: true, changeOrigin: true },
};

export default defineConfig({
  base: './',
  build: {
    outDir: 'dist',
    target: 'es2020',
    sourcemap: false,
    chunkSizeWarningLimit: 1200,
    rollupOptions: {
      output: { manualChunks: { echarts: ['echarts/core', 'echarts/charts', 'echarts/components', 'echarts/renderers'] } },
    },
  },
  plugins: [gzipAssets()],
  server: { proxy },
  preview: { proxy },
});
