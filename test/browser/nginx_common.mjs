// nginx for the browser tests: a config from gateway-config/ used as shipped except for what a site
// changes (ports, certificates, upstream addresses), replaced by exact text so that a config that no
// longer matches the test fails loudly; a self-signed certificate made by the test; the process
// started in the foreground and stopped by its PID.

import { execFileSync, spawn } from "node:child_process";
import fs from "node:fs";
import net from "node:net";
import path from "node:path";
import { ROOT, waitFor } from "./harness.mjs";

export const NGINX = ["/usr/sbin/nginx", "/usr/bin/nginx"].find((p) => fs.existsSync(p));
export const HAVE_OPENSSL = (() => { try { execFileSync("openssl", ["version"]); return true; } catch { return false; } })();

/**
 * A free TCP port on 127.0.0.1 below the ephemeral range (the kernel's bind-to-0 and outgoing connections
 * never take it), for nginx or a gateway that binds some time after the port is chosen.
 * @returns {Promise<number>}
 */
export async function freePort() {
  const low = Number(fs.readFileSync("/proc/sys/net/ipv4/ip_local_port_range", "utf8").split(/\s+/)[0]);
  for (let i = 0; i < 100; i++) {
    const port = 20000 + Math.floor(Math.random() * (Math.min(low, 29000) - 20000));
    const free = await new Promise((resolve) => {
      const srv = net.createServer();
      srv.once("error", () => resolve(false));
      srv.listen(port, "127.0.0.1", () => srv.close(() => resolve(true)));
    });
    if (free) return port;
  }
  throw new Error("no free port below the ephemeral range");
}

export function substitute(text, pairs) {
  for (const [from, to] of pairs) {
    if (!text.includes(from)) throw new Error(`${JSON.stringify(from)} not in the nginx config: this test no longer matches it`);
    text = text.replaceAll(from, to);
  }
  return text;
}

/** A self-signed certificate for `host` in `dir`: { cert, key }. */
export function selfSignedCert(dir, host) {
  const cert = path.join(dir, "cert.pem"), key = path.join(dir, "key.pem");
  execFileSync("openssl", ["req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
    "-days", "1", "-subj", `/CN=${host}`, "-addext", `subjectAltName=DNS:${host}`, "-keyout", key, "-out", cert],
  { stdio: "ignore" });
  return { cert, key };
}

/** Starts nginx on gateway-config/`file` with `pairs` replaced; resolves once `port` accepts. */
export async function startNginx(dir, file, pairs, port) {
  const conf = substitute(fs.readFileSync(path.join(ROOT, "gateway-config", file), "utf8"), pairs);
  fs.writeFileSync(path.join(dir, "site.conf"), conf);
  fs.writeFileSync(path.join(dir, "nginx.conf"), `pid ${dir}/nginx.pid;\nerror_log ${dir}/error.log;\nevents {}\nhttp {\n`
    + `  access_log ${dir}/access.log;\n  client_body_temp_path ${dir}/body;\n  proxy_temp_path ${dir}/proxy;\n`
    + `  include ${dir}/site.conf;\n}\n`);
  const proc = spawn(NGINX, ["-p", dir, "-c", path.join(dir, "nginx.conf"), "-g", "daemon off;"], { stdio: "ignore" });
  const exited = new Promise((r) => proc.once("exit", r));
  await Promise.race([
    waitFor(() => new Promise((resolve) => {
      const c = net.connect(port, "127.0.0.1", () => { c.destroy(); resolve(true); });
      c.on("error", () => resolve(false));
    }), "nginx listening"),
    exited.then(() => { throw new Error(`nginx exited: ${fs.existsSync(`${dir}/error.log`) ? fs.readFileSync(`${dir}/error.log`, "utf8") : ""}`); }),
  ]);
  return {
    proc,
    async stop() {
      if (proc.exitCode === null && proc.signalCode === null) {
        proc.kill("SIGTERM");
        await exited;
      }
    },
  };
}
