// Bundles src/main.jsx with React into dist/app.js (esbuild). robotraconteur-wasm stays a separate
// module (external): index.html maps it to rr/robotraconteur.mjs, where its .wasm file sits beside it.
import { build } from "esbuild";

await build({
  entryPoints: ["src/main.jsx"],
  bundle: true,
  format: "esm",
  jsx: "automatic",
  external: ["robotraconteur-wasm"],
  define: { "process.env.NODE_ENV": '"production"' },
  minify: true,
  sourcemap: true,
  target: ["es2022"],
  outfile: "dist/app.js",
  absWorkingDir: new URL(".", import.meta.url).pathname,
  logLevel: "warning",
});
console.log("built dist/app.js");
