// Message shapes of docs/studio.md (the contract with src/studio/service.cpp).
// Only what the front end reads is typed; everything else passes through.

export type Json = null | boolean | number | string | Json[] | { [k: string]: Json };

export interface ErrorReply {
  type: 'error';
  id?: number | string;
  code: string;
  message: string;
}

export interface DeviceProfile {
  name: string;
  description?: string;
  samples: number;
  spacing_mm: number;
  format: string;
  refresh_hz: number;
  band_min_cpm?: number;
  band_max_cpm?: number;
  layout?: { name: string; start_mm: number; length_mm: number }[];
  /** The display's frequency response (docs/format.md); absent = flat. */
  response?: { corner_hz: number; order: number; source?: string };
}

export interface ReferenceParam {
  key: string;
  unit?: string;
  default?: Json;
  [k: string]: Json | undefined;
}

export interface ReferenceInfo {
  name: string;
  description?: string;
  parameters?: ReferenceParam[];
}

export interface HelloReply {
  type: 'hello';
  version?: string;
  backend?: string;
  devices: DeviceProfile[];
  references: ReferenceInfo[];
  parameterizations?: string[];
  limits?: Record<string, number>;
}

export interface Spectrum {
  frequency_cpm: number[];
  magnitude_db: number[];
}

export interface DesignReply {
  type: 'design';
  id?: number | string;
  grid: { origin_mm: number; spacing_mm: number; count: number };
  map_f32: string;
  regions: { name: string; kind: string; start_mm: number; length_mm: number }[];
  /** Index of the analysed region (service.cpp; default the last Texel region). */
  region?: number;
  /** null when the analysed region is a reference. */
  histogram?: { edges_cpm: number[]; counts: number[]; pdf: number[] } | null;
  spectrum?: Spectrum;
  /** {bytes: null, error} when the region cannot be encoded; null for a reference region. */
  encoded?: { bytes: number | null; hex?: string; error?: string } | null;
  central_pitch_cpm?: number | null;
  irregularity_cpm?: number | null;
  texels?: number;
  elapsed_ms?: number;
}

/** service.cpp: `match {document, region: index, into?: index}`. */
export interface MatchReply {
  type: 'match';
  into: number;
  region: RegionDoc;
  document: TextureDocument;
  encoded: { bytes: number; hex: string; model_distance: number; [k: string]: Json };
  model_distance?: number;
  target_spectrum?: Spectrum;
  match_spectrum?: Spectrum;
  elapsed_ms?: number;
}

export interface FileReply {
  type: 'export';
  name: string;
  mime: string;
  data_base64: string;
}

export interface ImportReply {
  type: 'import';
  document: TextureDocument;
  [k: string]: Json | TextureDocument | undefined;
}

export interface FeelState {
  type: 'feel.state';
  position_mm: number | null;
  touching: boolean;
  blocks?: number;
  peak?: number;
  underruns?: number;
  backend?: string;
}

// ---- texture documents (docs/format.md)
export type CoarseProfile =
  | { kind: 'constant'; value?: number }
  | { kind: 'sine'; period_mm: number; phase_deg?: number }
  | { kind: 'points'; points: [number, number][] }
  | { kind: 'values'; values: number[] }
  | { kind: 'reference'; name: string; seed?: number; params?: Record<string, Json> };

export interface TexelTexture {
  kind: 'texel';
  central_pitch_db: number;
  irregularity_db: number;
  texel_length_mm: number;
  seed: number;
  parameterization?: 'moments' | 'log';
  quantization_db?: number;
  coarse?: CoarseProfile;
  coarse_strength?: number;
  fine_strength?: number;
  [k: string]: Json | CoarseProfile | undefined;
}

export interface ReferenceTexture {
  kind: 'reference';
  name: string;
  seed?: number;
  params?: Record<string, Json>;
}

export type Texture = TexelTexture | ReferenceTexture;

export interface RegionDoc {
  name: string;
  start_mm?: number;
  length_mm?: number;
  texture: Texture;
}

export interface TextureDocument {
  format: 'texel-document';
  version: number;
  description?: string;
  device: string | DeviceProfile;
  device_grid?: { length_mm: number; spacing_mm: number };
  texture?: Texture;
  regions?: RegionDoc[];
}

// ---- experiments
export interface StimulusQ {
  label: string;
  document?: TextureDocument;
}

export interface Question {
  trial: number;
  block_index: number;
  block: string;
  trial_in_block: number;
  block_trials: number;
  practice: boolean;
  task: string;
  prompt: string;
  /** Documents are withheld unless show_maps (they would give the answer away). */
  stimuli: StimulusQ[];
  choices: string[];
  rating_scale?: [number, number];
  sliders: { name: string; label: string; min: number; max: number; start: number }[];
  confidence: boolean;
  time_limit_s: number;
  show_maps: boolean;
  phases: { kind: string; stimulus: number; duration_s: number }[];
  matrix?: number[];
  recall_cell: number;
}

export interface SessionRef {
  id: number;
  participant: string;
  protocol: string;
}

export interface QuestionReply {
  type: 'experiment.question';
  session: SessionRef;
  progress: { done: number; planned: number };
  question: Question;
}

export interface FinishedReply {
  type: 'experiment.finished';
  session?: SessionRef;
  progress?: { done: number; planned: number };
}

export interface IdleReply {
  type: 'experiment.idle';
}

export type CurrentReply = QuestionReply | FinishedReply | IdleReply;

export interface SessionInfo {
  id: number;
  participant: string;
  protocol: string;
  finished: boolean;
  status?: string;
  trials_done: number;
  trials_planned: number;
}

export interface ListReply {
  type: 'experiment.list';
  protocols: { name: string; file?: string; study?: string }[];
  sessions: SessionInfo[];
  active: (SessionRef & { trials_done?: number; trials_planned?: number }) | null;
}

export interface TrialEvent {
  t_s: number;
  kind: string;
  detail: string;
  at: string;
}

/// Response::to_json / from_json (src/experiment/session.cpp) plus events.
export interface ResponseJson {
  choice?: string;
  rating?: number;
  confidence?: number;
  slider_p?: number;
  slider_i?: number;
  digit?: number;
  rt_ms?: number;
  shown_at: string;
  answered_at: string;
  events?: TrialEvent[];
}
