// Named stimuli: a designed texture kept under a name in this browser, so the
// protocol editor (experimenter view) can put it into a block as that block's
// `texture`. A protocol holds its textures inline (docs/experiments.md), so a
// stimulus is copied into the protocol when chosen — the protocol stays
// self-contained and a session's stored copy of it says exactly what was shown.

import { h } from './util';
import type { TextureDocument } from './document';

const KEY = 'texel.stimuli.v1';

export interface SavedStimulus {
  name: string;
  /** the document's `texture` object (one texture, as a protocol block takes it) */
  texture: Record<string, unknown>;
  device: string;
  saved_at: string;
}

export function listStimuli(): SavedStimulus[] {
  try {
    const v = JSON.parse(localStorage.getItem(KEY) ?? '[]');
    return Array.isArray(v) ? (v as SavedStimulus[]) : [];
  } catch {
    return [];
  }
}

const NAME = /^[A-Za-z0-9 ._-]{1,64}$/;

/** Saves the document's texture under `name` (replacing one of that name); returns an error text or null. */
export function saveStimulus(name: string, doc: TextureDocument): string | null {
  if (!NAME.test(name)) return 'Give the stimulus a name: 1 to 64 letters, digits, spaces, dots, dashes or underscores.';
  if (!doc.texture) return 'A stimulus is one texture: switch "Device and regions" to a single texture first.';
  const device = typeof doc.device === 'string' ? doc.device : doc.device.name;
  const all = listStimuli().filter((s) => s.name !== name);
  all.push({ name, texture: doc.texture as unknown as Record<string, unknown>, device, saved_at: new Date().toISOString() });
  localStorage.setItem(KEY, JSON.stringify(all));
  return null;
}

/** The designer's "Use as a stimulus" control: a name field and a button; `current` gives the design. */
export function stimulusSaver(current: () => TextureDocument): HTMLElement {
  const name = h('input', { id: 'stimulus-name', 'data-testid': 'stimulus-name', placeholder: 'e.g. fine-grating', autocomplete: 'off' }) as HTMLInputElement;
  const status = h('p', { class: 'hint', role: 'status', 'aria-live': 'polite', 'data-testid': 'stimulus-status' });
  const save = h('button', { type: 'button', 'data-testid': 'save-stimulus' }, 'Use as a stimulus') as HTMLButtonElement;
  save.addEventListener('click', () => {
    const err = saveStimulus(name.value.trim(), current());
    status.classList.toggle('error', !!err);
    status.textContent = err ?? `Saved "${name.value.trim()}": choose it for a block in the experimenter view's protocol editor.`;
  });
  return h('div', { class: 'ctl' }, h('label', { for: 'stimulus-name' }, 'Stimulus name'), h('div', { class: 'ctl-row' }, name, save), status);
}
