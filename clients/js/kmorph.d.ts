// kmorph.d.ts - types of kmorph.js, the client for the kmorph service.

export type Point = [number, number];

/** A curve as the service returns it: a B-spline or NURBS. */
export interface CurveOut {
  degree: number;
  knots: number[];
  control_points: Point[];
  weights?: number[];
  closed: boolean;
  svg_d?: string;
  [key: string]: unknown;
}

/** A curve as a request gives it (svg, polyline, bspline, shape...). */
export interface CurveIn {
  type: string;
  [key: string]: unknown;
}

export interface ShapeIn extends CurveIn {
  type: "shape";
  contours: CurveIn[];
  fill_rule?: "nonzero" | "evenodd";
}

/** What curve() takes: SVG path data, a list of contours, or a curve. */
export type CurveLike = string | Array<string | CurveIn> | CurveIn;

export interface Frame {
  t: number;
  curve?: CurveOut;
  contours?: Array<CurveOut | null>;
  svg_d?: string;
  [key: string]: unknown;
}

export interface MorphResult {
  method?: string;
  frames: Frame[];
  contour_matches_used?: Array<[number | null, number | null]>;
  [key: string]: unknown;
}

export interface MorphRequest {
  from: CurveIn;
  to: CurveIn;
  [key: string]: unknown;
}

export interface Problem {
  type?: string;
  title?: string;
  status?: number;
  detail?: string;
  errors?: Array<{ pointer?: string; message?: string }>;
  request_id?: string;
  [key: string]: unknown;
}

export interface JobStatus {
  id: string;
  state: "queued" | "running" | "done" | "failed" | "cancelled";
  progress?: number;
  frames_done?: number;
  frames_total?: number;
  error?: Problem;
  location?: string | null;
  [key: string]: unknown;
}

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
  errors: Array<{ pointer?: string; message?: string }>;
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

export interface Signal {
  signal?: AbortSignal;
}

export class Client {
  constructor(options?: ClientOptions);
  baseUrl: string;
  fetch: typeof fetch;
  headers: Record<string, string>;
  pollInterval: number;
  maxPollInterval: number;
  request(method: string, path: string,
          options?: { body?: unknown; signal?: AbortSignal; accept?: string }): Promise<{ response: Response; body: any }>;
  signature(curve: CurveIn, options?: { tolerance?: number; samples?: number } & Signal): Promise<any>;
  reconstruct(signature: unknown,
              options?: { tolerance?: number; degree?: 3 | 5; include?: string[] } & Signal): Promise<any>;
  morph(request: MorphRequest, options?: Signal): Promise<MorphResult | string>;
  submitJob(request: MorphRequest, options?: Signal): Promise<JobStatus>;
  job(id: string, options?: Signal): Promise<JobStatus>;
  jobResult(id: string, options?: Signal): Promise<MorphResult | string>;
  cancelJob(id: string, options?: Signal): Promise<void>;
  morphJob(request: MorphRequest,
           options?: { onProgress?: (status: JobStatus) => void } & Signal): Promise<MorphResult | string>;
  health(options?: Signal): Promise<any>;
  ready(options?: Signal): Promise<any>;
}

export function curve(input: CurveLike): CurveIn;
export function pathContours(d: string, options?: { close?: boolean }): string[];
export function shape(contours: string | Array<string | CurveIn>,
                      options?: { fillRule?: "nonzero" | "evenodd" }): ShapeIn;
export function morphRequest(from: CurveLike, to: CurveLike, options?: Record<string, unknown>): MorphRequest;

export function evalCurve(curve: CurveOut, u: number, k?: number): [Point, Point];
export function curveToPath(curve: CurveOut, options?: { pieces?: number }): string;
export function samplePoints(curve: CurveOut, n?: number, options?: { perSpan?: number }): Point[];

export function isCompound(resultOrFrame: MorphResult | Frame): boolean;
export function contourPairs(result: MorphResult): Array<{ slot: number; from: number | null; to: number | null }>;
export function frameContours(frame: Frame): Array<CurveOut | null>;
export function frameContourPaths(frame: Frame, options?: { pieces?: number }): Array<string | null>;
export function framePath(frame: Frame, options?: { pieces?: number }): string;
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

export function signature(curve: CurveIn, options?: { tolerance?: number; samples?: number } & Signal): Promise<any>;
export function reconstruct(signature: unknown,
                            options?: { tolerance?: number; degree?: 3 | 5; include?: string[] } & Signal): Promise<any>;
export function morph(request: MorphRequest, options?: Signal): Promise<MorphResult | string>;
export function morphJob(request: MorphRequest,
                         options?: { onProgress?: (status: JobStatus) => void } & Signal): Promise<MorphResult | string>;
