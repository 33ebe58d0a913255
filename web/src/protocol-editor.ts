// The experimenter view's protocol editor: a form generated from the
// protocol's JSON Schema (docs/schema/texel-protocol.schema.json, bundled at
// build time), filled from a shipped protocol as a template. Scalars get
// inputs (enum → select, number → number field with the schema's range,
// boolean → checkbox, const → shown, not editable); objects and lists the
// schema nests deeper (textures, staircases, pairs) get a JSON field checked
// as it is typed. A block's fields are those of its task's branch of the
// schema. The engine's own validation (`experiment.validate`) is the judge:
// the browser's checks only catch typing mistakes early.

import schemaText from '../../docs/schema/texel-protocol.schema.json?raw';
import { h } from './util';
import { listStimuli } from './stimuli';

type Json = null | boolean | number | string | Json[] | { [k: string]: Json };
type Obj = { [k: string]: Json };
interface Schema {
  type?: string | string[];
  enum?: Json[];
  const?: Json;
  properties?: Record<string, Schema>;
  required?: string[];
  oneOf?: Schema[];
  $ref?: string;
  minimum?: number;
  maximum?: number;
  description?: string;
  default?: Json;
  items?: Schema;
  $defs?: Record<string, Schema>;
}

const schema = JSON.parse(schemaText) as Schema;

function resolve(s: Schema): Schema {
  if (s.$ref?.startsWith('#/$defs/')) return resolve(schema.$defs![s.$ref.slice(8)] ?? {});
  return s;
}

/** The block schemas by task (the `task` const of each branch of blocks.items.oneOf). */
const blockSchemas = new Map<string, Schema>();
for (const b of resolve(schema.properties!.blocks).items?.oneOf ?? []) {
  const r = resolve(b);
  const task = r.properties?.task?.const;
  if (typeof task === 'string') blockSchemas.set(task, r);
}

let uid = 0;

/**
 * A path as the form names it: the engine's 0-based "blocks[0].time_limit_s" is "Block 1 › time_limit_s",
 * as the block's legend says ("Block 1: …"); nested lists stay as the engine gives them.
 */
export function formPath(path: string): string {
  return path
    .replace(/^protocol\./, '')
    .replace(/\bblocks\[(\d+)\]\.?/g, (_, n: string) => `Block ${Number(n) + 1} › `)
    .replace(/ › $/, '');
}

/** The engine's message with every block path 1-based, as the form shows blocks. */
export function formMessage(message: string): string {
  return message.replace(/\bblocks\[(\d+)\](\.[A-Za-z_][\w.[\]]*)?/g, (m) => formPath(m));
}

const clone = <T>(v: T): T => JSON.parse(JSON.stringify(v)) as T;
const label = (key: string) => key.replace(/_/g, ' ');

export interface ProtocolEditor {
  el: HTMLElement;
  /** Replaces the protocol being edited (a template). */
  load(p: Obj): void;
  /** The protocol as the form holds it, or an error naming the first field that is not valid JSON. */
  value(): { protocol: Obj } | { error: string };
  /**
   * Shows the engine's refusal at the field it names ("blocks[0].time_limit_s …" at Block 1's
   * time_limit_s; a top-level key at the protocol's field) and returns the message as the form words
   * it (1-based blocks); false when no field of the form matches (the caller shows it elsewhere).
   */
  showError(message: string): { text: string; atField: boolean };
  /** Removes every refusal shown at a field. */
  clearErrors(): void;
}

export function protocolEditor(): ProtocolEditor {
  let proto: Obj = {};
  const broken = new Map<string, string>(); // field id → JSON error
  const form = h('div', { class: 'protocol-form', 'data-testid': 'protocol-form' });

  /** The slot at a field where the engine's refusal of it is shown (showError). */
  const engineError = (id: string) => h('p', { class: 'field-error engine-error', id: `${id}-engine`, role: 'alert', hidden: true, 'data-testid': 'field-error' });

  /** One input for `obj[key]` described by `s`. */
  function field(obj: Obj, key: string, s0: Schema, required: boolean, path: string): HTMLElement {
    const s = resolve(s0);
    const id = `pf-${++uid}`;
    const hintId = `${id}-hint`;
    const v = obj[key];
    const set = (x: Json | undefined) => {
      if (x === undefined) delete obj[key];
      else obj[key] = x;
    };
    const hint = s.description || s0.description;
    const lab = h('label', { for: id }, label(key), required ? '' : h('span', { class: 'unit' }, ' (optional)'));
    const wrap = (input: HTMLElement, ...extra: (HTMLElement | null)[]) =>
      h('div', { class: 'ctl', 'data-field': path }, lab, input, ...extra, hint ? h('p', { class: 'hint', id: hintId }, hint) : null, engineError(id));
    const described = hint ? hintId : undefined;

    if (s.const !== undefined) {
      if (v === undefined && required) obj[key] = s.const;
      return h('div', { class: 'ctl', 'data-field': path }, h('span', {}, `${label(key)}: `), h('code', {}, JSON.stringify(s.const)));
    }
    if (s.enum) {
      const sel = h('select', { id, 'aria-describedby': described }) as HTMLSelectElement;
      if (!required) sel.append(h('option', { value: '' }, '(not set)'));
      for (const e of s.enum) sel.append(h('option', { value: JSON.stringify(e) }, String(e)));
      sel.value = v === undefined ? '' : JSON.stringify(v);
      sel.addEventListener('change', () => set(sel.value === '' ? undefined : (JSON.parse(sel.value) as Json)));
      return wrap(sel);
    }
    const type = Array.isArray(s.type) ? s.type[0] : s.type;
    if (type === 'string') {
      const long = key === 'description' || key === 'prompt';
      const input = (long ? h('textarea', { id, rows: 2, 'aria-describedby': described }) : h('input', { id, 'aria-describedby': described, autocomplete: 'off' })) as HTMLInputElement;
      input.value = typeof v === 'string' ? v : '';
      if (required) input.required = true;
      input.addEventListener('input', () => set(input.value === '' && !required ? undefined : input.value));
      return wrap(input);
    }
    if (type === 'number' || type === 'integer') {
      const input = h('input', { id, type: 'number', class: 'num', step: type === 'integer' ? 1 : 'any', 'aria-describedby': described }) as HTMLInputElement;
      if (s.minimum !== undefined) input.min = String(s.minimum);
      if (s.maximum !== undefined) input.max = String(s.maximum);
      input.value = typeof v === 'number' ? String(v) : '';
      input.placeholder = s.default !== undefined ? String(s.default) : '';
      input.addEventListener('input', () => set(input.value === '' ? undefined : Number(input.value)));
      return wrap(input);
    }
    if (type === 'boolean') {
      const input = h('input', { id, type: 'checkbox', 'aria-describedby': described }) as HTMLInputElement;
      input.checked = v === undefined ? s.default === true : v === true;
      input.addEventListener('change', () => set(input.checked));
      return h('div', { class: 'ctl', 'data-field': path }, h('label', { class: 'inline', for: id }, input, ` ${label(key)}`), hint ? h('p', { class: 'hint', id: hintId }, hint) : null, engineError(id));
    }
    // Deeper structures: a JSON field, checked as it is typed.
    const area = h('textarea', { id, rows: 4, class: 'json', spellcheck: 'false', 'aria-describedby': `${id}-err${described ? ` ${described}` : ''}` }) as HTMLTextAreaElement;
    area.value = v === undefined ? '' : JSON.stringify(v, null, 1);
    const err = h('p', { class: 'hint field-error', id: `${id}-err`, role: 'alert' });
    area.addEventListener('input', () => {
      if (area.value.trim() === '') {
        set(undefined);
        broken.delete(id);
        err.textContent = '';
        return;
      }
      try {
        set(JSON.parse(area.value) as Json);
        broken.delete(id);
        err.textContent = '';
        area.removeAttribute('aria-invalid');
      } catch (e) {
        const msg = `${formPath(path)} is not valid JSON (${e instanceof Error ? e.message : String(e)})`;
        broken.set(id, msg);
        err.textContent = msg;
        area.setAttribute('aria-invalid', 'true');
      }
    });
    let pick: HTMLElement | null = null;
    if (key === 'texture' || key === 'different') {
      const stimuli = listStimuli();
      const sel = h('select', { id: `${id}-stimulus`, 'data-testid': 'use-stimulus' }, h('option', { value: '' }, stimuli.length ? 'choose…' : 'none saved yet (designer: "Use as a stimulus")')) as HTMLSelectElement;
      for (const st of stimuli) sel.append(h('option', { value: st.name }, `${st.name} (${st.device})`));
      sel.addEventListener('change', () => {
        const st = listStimuli().find((x) => x.name === sel.value);
        if (!st) return;
        set(clone(st.texture) as Json);
        area.value = JSON.stringify(st.texture, null, 1);
        area.dispatchEvent(new Event('input'));
      });
      pick = h('div', { class: 'ctl-row' }, h('label', { for: `${id}-stimulus` }, 'Saved stimulus'), sel);
    }
    return wrap(area, pick, err);
  }

  function objectFields(obj: Obj, s: Schema, path: string, skip: string[] = []): HTMLElement[] {
    const req = new Set(s.required ?? []);
    return Object.entries(s.properties ?? {})
      .filter(([k]) => !skip.includes(k))
      .map(([k, ps]) => field(obj, k, ps, req.has(k), `${path}.${k}`));
  }

  function blockFieldset(blocks: Obj[], i: number): HTMLElement {
    const b = blocks[i];
    const task = String(b.task ?? '');
    const bs = blockSchemas.get(task);
    const id = `pf-${++uid}`;
    const taskSel = h('select', { id, 'data-testid': 'block-task' }) as HTMLSelectElement;
    for (const t of blockSchemas.keys()) taskSel.append(h('option', { value: t }, t));
    taskSel.value = task;
    taskSel.addEventListener('change', () => {
      // Keep what the new task also has; the rest belongs to the old task.
      const keep = blockSchemas.get(taskSel.value)?.properties ?? {};
      for (const k of Object.keys(b)) if (!(k in keep)) delete b[k];
      b.task = taskSel.value;
      render();
    });
    const remove = h('button', { type: 'button', 'aria-label': `Remove block ${i + 1}` }, 'Remove block') as HTMLButtonElement;
    remove.disabled = blocks.length <= 1;
    remove.addEventListener('click', () => {
      blocks.splice(i, 1);
      render();
    });
    return h(
      'fieldset',
      { class: 'block', 'data-testid': 'protocol-block' },
      h('legend', {}, `Block ${i + 1}: ${String(b.name ?? '')}`),
      h('div', { class: 'ctl' }, h('label', { for: id }, 'task'), taskSel),
      ...(bs ? objectFields(b, bs, `blocks[${i}]`, ['task']) : [h('p', { class: 'hint' }, `unknown task ${task}`)]),
      remove,
    );
  }

  function render(): void {
    broken.clear();
    const blocks = (Array.isArray(proto.blocks) ? proto.blocks : (proto.blocks = [])) as Obj[];
    const add = h('button', { type: 'button', 'data-testid': 'add-block' }, 'Add a block (a copy of the last)');
    add.addEventListener('click', () => {
      blocks.push(clone(blocks[blocks.length - 1] ?? { name: 'block', task: [...blockSchemas.keys()][0] }));
      blocks[blocks.length - 1].name = `block-${blocks.length}`;
      render();
    });
    form.replaceChildren(
      h('fieldset', {}, h('legend', {}, 'Protocol'), ...objectFields(proto, schema, 'protocol', ['blocks'])),
      ...blocks.map((_, i) => blockFieldset(blocks, i)),
      add,
    );
  }

  function clearErrors(): void {
    for (const e of form.querySelectorAll<HTMLElement>('.engine-error')) {
      e.hidden = true;
      e.textContent = '';
    }
    for (const e of form.querySelectorAll('[data-engine-invalid]')) {
      e.removeAttribute('aria-invalid');
      e.removeAttribute('data-engine-invalid');
    }
  }

  /** The form's field for the engine's path: the longest path the message names that the form has. */
  function fieldFor(message: string): HTMLElement | null {
    const paths = message.match(/\b[a-z_]+(\[\d+\])?(\.[a-z_]+(\[\d+\])?)*/g) ?? [];
    for (const p of paths) {
      // "blocks[0].staircase.step_mm": the form's field is "blocks[0].staircase" (a JSON field) if not the whole path.
      const parts = p.split('.');
      for (let n = parts.length; n > 0; n--) {
        const at = parts.slice(0, n).join('.');
        // A protocol's own fields are "protocol.<key>" in the form.
        for (const q of at.startsWith('blocks[') ? [at] : [at, `protocol.${at}`]) {
          const el = form.querySelector<HTMLElement>(`[data-field="${CSS.escape(q)}"]`);
          if (el) return el;
        }
      }
    }
    return null;
  }

  return {
    el: form,
    load(p) {
      proto = clone(p);
      render();
    },
    showError(message) {
      clearErrors();
      const text = formMessage(message);
      const at = fieldFor(message);
      const slot = at?.querySelector<HTMLElement>(':scope > .engine-error');
      if (!at || !slot) return { text, atField: false };
      slot.textContent = text;
      slot.hidden = false;
      const input = at.querySelector<HTMLElement>('input, select, textarea');
      if (input) {
        input.setAttribute('aria-invalid', 'true');
        input.setAttribute('data-engine-invalid', '');
        // The refusal stays until the field changes.
        input.addEventListener('input', () => clearErrors(), { once: true });
        input.addEventListener('change', () => clearErrors(), { once: true });
      }
      at.scrollIntoView({ block: 'nearest' });
      return { text, atField: true };
    },
    clearErrors,
    value() {
      const first = [...broken.values()][0];
      return first ? { error: first } : { protocol: clone(proto) };
    },
  };
}
