// Vite build of the dashboard into dist/ (index.html + hashed assets), served by `synbench serve`.
// `npm run dev` / `npm run preview` proxy /api and /ws to a running daemon (SYNBENCH_URL, default
// http://127.0.0.1:8080) so the page stays same-origin; the e2e test uses the preview proxy only
// when the daemon it starts does not serve web/dist itself.
import { defineConfig } from 'vite';

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
  server: { proxy },
  preview: { proxy },
});
