// daemon.mjs - start build/kmorphd (or $KMORPHD) on a free loopback port for
// the JavaScript and browser client tests, and stop it again. Every wait is
// bounded in time.
import { spawn } from "node:child_process";
import path from "node:path";
import { fileURLToPath } from "node:url";

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../../..");

/** Start a daemon with extra flags; resolves to {url, port, stop(), log()}.
 * The OS picks the port (--port 0); the daemon prints it on stderr. */
export function startDaemon(flags = [], { timeoutMs = 10000 } = {}) {
  const bin = process.env.KMORPHD || path.join(ROOT, "build", "kmorphd");
  const env = Object.fromEntries(Object.entries(process.env).filter(([k]) => !k.startsWith("KMORPH_")));
  const child = spawn(bin, ["--bind", "127.0.0.1", "--port", "0",
                            "--web-root", path.join(ROOT, "clients", "web"), ...flags],
                      { env, stdio: ["ignore", "ignore", "pipe"] });
  let text = "";
  let started = false;
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => { child.kill("SIGKILL"); reject(new Error("kmorphd did not start: " + text)); }, timeoutMs);
    child.on("exit", (code) => { clearTimeout(timer); reject(new Error(`kmorphd exited (${code}): ${text}`)); });
    child.stderr.on("data", (chunk) => {
      text += chunk;
      if (text.length > 1 << 20) text = text.slice(-(1 << 19));
      const m = /listening on (http:\/\/[^\s]+:(\d+))/.exec(text);
      if (m && !started) {
        started = true;
        clearTimeout(timer);
        child.removeAllListeners("exit");
        resolve({
          url: m[1], port: Number(m[2]), log: () => text,
          stop: () => new Promise((done) => {
            if (child.exitCode !== null) return done();
            const kill = setTimeout(() => child.kill("SIGKILL"), 5000);
            child.once("exit", () => { clearTimeout(kill); done(); });
            child.kill("SIGTERM");
          }),
        });
      }
    });
  });
}
