// The form: one fieldset per schema group with a control per field, each showing its
// value, whether it is changed, and whether the chosen MDF and source read it.
import { $, h } from './dom.js';
import { vectorControl } from './color.js';
import { boolControl, enumControl, numberControl, textControl } from './inputs.js';
import { pickControl } from './picker.js';
import { state, valueOf } from './state.js';

const BUILDERS = { number: numberControl, enum: enumControl, bool: boolControl,
  vector: vectorControl, text: textControl, pick: pickControl };
// Groups shown folded (their fields are rarely set by hand).
const FOLDED = new Set(['tier']);

export function buildControls() {
  const root = $('#groups');
  for (const { id, title, fields } of state.groups) {
    if (!fields.length) continue;
    const set = h('fieldset', { class: `group group-${id}`, id: `group-${id}` },
      h('legend', { text: title }));
    for (const name of fields) {
      const spec = state.specs.get(name);
      const control = BUILDERS[spec.kind](spec);
      state.controls.set(name, control);
      set.append(control.wrap);
    }
    if (FOLDED.has(id)) {
      root.append(h('details', { class: 'group-details' }, h('summary', { text: title }), set));
    } else root.append(set);
  }
}

export function refreshField(name, source) {
  const control = state.controls.get(name);
  if (!control) return;
  control.show(valueOf(name), source);
  // Quick pickers elsewhere on the page (data-mirrors) show the same value.
  // A value none of its options has (a file's name) gets an option of its own, where the
  // first option ("the preset's lights") had been shown.
  for (const mirror of document.querySelectorAll(`select[data-mirrors="${name}"]`)) {
    const value = valueOf(name) ?? mirror.options[0].value;
    let own = mirror.querySelector('option[data-own]');
    if (![...mirror.options].some((o) => o.value === value && o !== own)) {
      if (!own) mirror.append(own = h('option', { 'data-own': '' }));
      own.value = value;
      own.textContent = `file: ${value}`;
    } else if (own) own.remove();
    mirror.value = value;
  }
  const changed = name in state.overrides;
  control.wrap.classList.toggle('changed', changed);
  control.reset.hidden = !changed;
}

// A field's selector value, or null while the selector itself is unused (the physical
// sources read no MDF choice, so a field that needs an MDF is then not held back by it).
function selected(name, seen = new Set()) {
  const spec = state.specs.get(name);
  if (!spec || seen.has(name)) return null;
  if (unusedBy(spec, new Set([...seen, name]))) return null;
  return valueOf(name) ?? spec.default;
}

// The selector value under which a field goes unread (x-applies), or null if it is read.
function unusedBy(spec, seen = new Set()) {
  for (const [selector, values] of Object.entries(spec.applies || {})) {
    const value = selected(selector, seen);
    if (value !== null && !values.includes(value)) return value;
  }
  return null;
}

export function refreshInactive() {
  for (const [name, control] of state.controls) {
    const by = unusedBy(state.specs.get(name));
    control.wrap.classList.toggle('inactive', by !== null);
    control.wrap.querySelector('.note').textContent = by !== null ? `unused by ${by}` : '';
  }
}

export function refreshAll() {
  for (const name of state.controls.keys()) refreshField(name, null);
  refreshInactive();
}
