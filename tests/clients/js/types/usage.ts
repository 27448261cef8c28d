// usage.ts - the kmorph package's types as a TypeScript program sees
// them, checked by tsc --noEmit (package.test.mjs): what the contract
// allows compiles, and each `@ts-expect-error` line is something the
// contract refuses - tsc fails if it ever compiles, so the types cannot
// quietly decay to `any`.
import {
  Client,
  KmorphError,
  interpolate,
  morphRequest,
  type Health,
  type MorphRequest,
  type MorphResult,
  type Problem,
  type Schemas,
  type paths,
} from "../../../../clients/js/kmorph.js";

const client = new Client({ baseUrl: "http://127.0.0.1:8080" });
const request: MorphRequest = morphRequest("M 0 0 L 1 0", "M 0 0 L 0 1", {
  frames: 5,
  method: "curvature",
});

// Members with a default (intersections, method, ...) may be left out.
export const minimal: MorphRequest = {
  from: { type: "svg", d: "M 0 0 L 1 0" },
  to: { type: "points", points: [[0, 0], [0, 1]] },
};

// @ts-expect-error the method is "curvature" or "linear"
export const badMethod: MorphRequest = { ...request, method: "bogus" };
// @ts-expect-error frames is a number
morphRequest("M 0 0 L 1 0", "M 0 0 L 0 1", { frames: "5" });
// @ts-expect-error a request needs both ends
export const noEnd: MorphRequest = { from: request.from };

// The body of POST /v1/morph, from the paths of the contract, is the
// MorphRequest schema.
type MorphBody = paths["/v1/morph"]["post"]["requestBody"]["content"]["application/json"];
export const sameBody: MorphBody = request;

export async function use(): Promise<string> {
  const result = await client.morph(request);
  if (typeof result !== "string") {
    const morph: MorphResult = result;
    const t: number = morph.frames[0].t;
    // @ts-expect-error a result has no such member
    morph.frame_count;
    void t;
  }
  const sig = await client.signature({ type: "svg", d: "M 0 0 L 1 0" });
  if ("signature" in sig) {
    const length: number = sig.signature.length;
    const start: [number, number] = sig.signature.start.point;
    void length;
    void start;
    const curve = (await client.reconstruct(sig.signature, { degree: 5 })).curve;
    const closed: boolean = curve.closed;
    void closed;
  }
  // @ts-expect-error the degree is 3 or 5
  await client.reconstruct({} as Schemas["Signature"], { degree: 4 });
  const health: Health = await client.health();
  const status: "ok" | "ready" = health.status;
  void status;
  try {
    await client.job("0");
  } catch (e) {
    if (e instanceof KmorphError) {
      const problem: Problem = e.problem;
      const pointers: string[] = e.errors.map((x) => x.pointer);
      void problem;
      void pointers;
    }
  }
  const at = await interpolate("M 0 0 L 1 0", "M 0 0 L 0 1", { client, frames: 3 });
  return String(at(0.5));
}
