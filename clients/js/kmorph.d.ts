// kmorph.d.ts - types of kmorph.js, the client for the kmorph service.
//
// The request and response bodies are the contract's own schemas:
// openapi.d.ts is generated from api/openapi.yaml by openapi-typescript
// when the package is packed (npm run types), so a type here cannot drift
// from what the service answers. Every schema is exported under its name
// in the contract; `paths` and `operations` describe each endpoint.

import type { components, operations, paths } from "./openapi.js";

export type { components, operations, paths };

/** Every schema of the contract, by name (components.schemas). */
export type Schemas = components["schemas"];

export type Point = Schemas["Point"];
export type Fraction = Schemas["Fraction"];
export type Tolerance = Schemas["Tolerance"];
export type Precision = Schemas["Precision"];
export type BsplineCurve = Schemas["BsplineCurve"];
export type SvgCurve = Schemas["SvgCurve"];
export type PointsCurve = Schemas["PointsCurve"];
export type SignatureCurve = Schemas["SignatureCurve"];
export type Contour = Schemas["Contour"];
export type ShapeCurve = Schemas["ShapeCurve"];
export type Curve = Schemas["Curve"];
export type CurveOut = Schemas["CurveOut"];
export type ScalarSpline = Schemas["ScalarSpline"];
export type Corner = Schemas["Corner"];
export type Signature = Schemas["Signature"];
export type SignatureRequest = Schemas["SignatureRequest"];
export type SignatureResponse = Schemas["SignatureResponse"];
export type CurveSignatureResponse = Schemas["CurveSignatureResponse"];
export type ShapeSignatureResponse = Schemas["ShapeSignatureResponse"];
export type ReconstructRequest = Schemas["ReconstructRequest"];
export type ReconstructResponse = Schemas["ReconstructResponse"];
export type MorphRequest = Schemas["MorphRequest"];
export type FrameMetrics = Schemas["FrameMetrics"];
export type ContourPair = Schemas["ContourPair"];
export type ShapeFrameMetrics = Schemas["ShapeFrameMetrics"];
export type ShapeFrame = Schemas["ShapeFrame"];
export type Frame = Schemas["Frame"];
export type MorphResult = Schemas["MorphResult"];
export type IntersectionsReport = Schemas["IntersectionsReport"];
export type JobStatus = Schemas["JobStatus"];
export type Health = Schemas["Health"];
export type Problem = Schemas["Problem"];
export type ProblemType = Schemas["ProblemType"];

/** A curve as a request gives it (svg, points, bspline, signature, shape). */
export type CurveIn = Curve;
/** A compound shape as a request gives it. */
export type ShapeIn = ShapeCurve;
/** A frame of a morph: of one curve, or of a shape (one curve per slot). */
export type AnyFrame = Frame | ShapeFrame;

/** What curve() takes: SVG path data, a list of contours, or a curve. */
export type CurveLike = string | Array<string | CurveIn> | CurveIn;

/** The place in a request a problem's error points at, per contour. */
export interface ContourError {
  side: "from" | "to" | "curve";
  contour: number;
  offset: number | null;
  pointer: string;
  message: string;
}

export class KmorphError extends Error {
  constructor(problem: Problem | null | undefined, response?: Response);
  name: "KmorphError";
  problem: Problem;
  status: number;
  type: string;
  title: string;
  detail: string;
  errors: NonNullable<Problem["errors"]>;
  requestId: string | null;
  retryAfter: number | null;
  messageFor(pointer: string): string | null;
  contourErrors(): ContourError[];
}

export interface ClientOptions {
  baseUrl?: string;
  fetch?: typeof fetch;
  headers?: Record<string, string>;
  pollInterval?: number;
  maxPollInterval?: number;
}

/** Bytes of an answer read so far; total is null when unknown (a
 * compressed body). */
export interface DownloadProgress { received: number; total: number | null; }
export interface Download { onDownload?: (progress: DownloadProgress) => void; }

export interface Signal {
  signal?: AbortSignal;
}

/** The members of a signature request besides the curve. */
export type SignatureOptions = Omit<SignatureRequest, "curve">;
/** The members of a reconstruct request besides the signature; include
 * (["svg_d"]) as in a morph request. */
export type ReconstructOptions = Omit<ReconstructRequest, "signature"> & Pick<MorphRequest, "include">;

export class Client {
  constructor(options?: ClientOptions);
  baseUrl: string;
  fetch: typeof fetch;
  headers: Record<string, string>;
  pollInterval: number;
  maxPollInterval: number;
  request(method: string, path: string,
          options?: { body?: unknown; signal?: AbortSignal; accept?: string } & Download): Promise<{ response: Response; body: unknown }>;
  signature(curve: CurveIn, options?: SignatureOptions & Signal): Promise<SignatureResponse>;
  reconstruct(signature: Signature,
              options?: ReconstructOptions & Signal): Promise<ReconstructResponse>;
  morph(request: MorphRequest, options?: Signal & Download): Promise<MorphResult | string>;
  submitJob(request: MorphRequest, options?: Signal): Promise<JobStatus>;
  job(id: string, options?: Signal): Promise<JobStatus>;
  jobResult(id: string, options?: Signal & Download): Promise<MorphResult | string>;
  cancelJob(id: string, options?: Signal): Promise<void>;
  morphJob(request: MorphRequest,
           options?: { onProgress?: (status: JobStatus) => void } & Signal & Download): Promise<MorphResult | string>;
  health(options?: Signal): Promise<Health>;
  ready(options?: Signal): Promise<Health>;
}

export function curve(input: CurveLike): CurveIn;
export function pathContours(d: string, options?: { close?: boolean }): string[];
export function shape(contours: string | Array<string | CurveIn>,
                      options?: { fillRule?: "nonzero" | "evenodd" }): ShapeIn;
export function morphRequest(from: CurveLike, to: CurveLike,
                             options?: Partial<Omit<MorphRequest, "from" | "to">>): MorphRequest;

export function evalCurve(curve: CurveOut, u: number, k?: number): [Point, Point];
export function curveToPath(curve: CurveOut, options?: { pieces?: number }): string;
export function samplePoints(curve: CurveOut, n?: number, options?: { perSpan?: number }): Point[];

export function isCompound(resultOrFrame: MorphResult | AnyFrame): boolean;
export function contourPairs(result: MorphResult): Array<{ slot: number; from: number | null; to: number | null }>;
export function frameContours(frame: AnyFrame): Array<CurveOut | null>;
export function frameContourPaths(frame: AnyFrame, options?: { pieces?: number }): Array<string | null>;
export function framePath(frame: AnyFrame, options?: { pieces?: number }): string;
export function framePaths(result: MorphResult, options?: { pieces?: number }): string[];

export interface InterpolatorOptions {
  samples?: number;
  exact?: boolean;
  collapsed?: "point" | "omit";
  perContour?: boolean;
  /** false: blended points instead of path data. */
  string?: boolean;
}

/** t in [0, 1] -> path data (or, with string: false, points: Point[] for
 * a single curve, one Point[] or null per slot for a shape or with
 * perContour). */
export type Interpolator = (t: number) => any;

export function interpolator(result: MorphResult, options?: InterpolatorOptions): Interpolator;

export interface InterpolateOptions extends InterpolatorOptions, Signal {
  client?: Client;
  frames?: number;
  times?: number[];
  [field: string]: unknown;
}

export function interpolate(from: CurveLike, to: CurveLike, options?: InterpolateOptions): Promise<Interpolator>;
export function interpolateAll(froms: CurveLike[], tos: CurveLike[],
                               options?: InterpolateOptions & { single?: false }): Promise<Interpolator[]>;
export function interpolateAll(froms: CurveLike[], tos: CurveLike[],
                               options: InterpolateOptions & { single: true }): Promise<Interpolator>;

export function bounds(result: MorphResult): [number, number, number, number];

export function signature(curve: CurveIn, options?: SignatureOptions & Signal): Promise<SignatureResponse>;
export function reconstruct(signature: unknown,
                            options?: { tolerance?: number; degree?: 3 | 5; include?: string[] } & Signal): Promise<any>;
export function morph(request: MorphRequest, options?: Signal): Promise<MorphResult | string>;
export function morphJob(request: MorphRequest,
                         options?: { onProgress?: (status: JobStatus) => void } & Signal): Promise<MorphResult | string>;
