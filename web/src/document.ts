// Texture documents as the designer builds them (docs/format.md,
// docs/schema/texel-document.schema.json). The messages that carry them are
// generated from the message schema (generated/messages.ts).
import type { DeviceProfile } from './generated/messages';

export type Json = null | boolean | number | string | Json[] | { [k: string]: Json };

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
  out_of_band?: 'redraw' | 'clamp';
  band_min_cpm?: number;
  band_max_cpm?: number;
  phase?: 'continuous' | 'reset';
  fill?: 'whole' | 'partial';
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

