// Error lines shown by the control they are about (a 422's `fields` say which), the rest
// by the preview; and the status line under it.
import { $, h } from './dom.js';
import { state } from './state.js';

export const setStatus = (text) => { $('#status').textContent = text; };

// Where a field's problems go: its control, the preset picker, or else the preview.
const placeOf = (field) => (field === 'preset' || state.controls.has(field) ? field : 'general');

// problems: [{ lines, fields }] as api.problemOf reads them; each line shown once.
export function routeErrors(problems) {
  const byPlace = new Map();
  const add = (place, line) => {
    const list = byPlace.get(place) || [];
    if (![...byPlace.values()].some((shown) => shown.includes(line))) byPlace.set(place, [...list, line]);
  };
  for (const { fields = [] } of problems) for (const f of fields) add(placeOf(f.field), f.message);
  // A problem the service answers without fields (a 404's unknown environment or mesh, a
  // map that cannot be read) is shown by its control when its line starts with the field's
  // name, as every message does ("environment='x' is not known", "environment x.hdr: …").
  for (const { lines, fields = [] } of problems) {
    for (const line of lines) {
      const named = fields.length ? null : /^([a-z][a-z0-9_]*)[= ]/.exec(line);
      add(named && state.controls.has(named[1]) ? named[1] : 'general', line);
    }
  }
  for (const [place, lines] of byPlace) showError(place, lines);
  return [...byPlace.keys()].filter((place) => state.controls.has(place));
}

export function showError(name, lines) {
  const err = $(`#err-${name}`);
  if (!err) return;
  err.textContent = lines.join('\n');
  err.hidden = false;
  const control = state.controls.get(name);
  if (control) {
    control.wrap.classList.add('has-error');
    for (const input of control.inputs) input.setAttribute('aria-invalid', 'true');
  }
  if (name === 'preset') $('#preset').setAttribute('aria-invalid', 'true');
}

export function clearErrors() {
  for (const err of document.querySelectorAll('.error[id^="err-"]')) {
    err.hidden = true;
    err.textContent = '';
  }
  for (const node of document.querySelectorAll('.has-error')) node.classList.remove('has-error');
  for (const node of document.querySelectorAll('[aria-invalid]')) node.removeAttribute('aria-invalid');
}

// "Showing the last good image; see ex, albedo", each name a link to its control.
export function showProblemSummary(names) {
  const status = $('#status');
  status.textContent = `Showing the last good image${names.length ? '; see ' : '.'}`;
  names.forEach((name, i) => {
    const input = state.controls.get(name).inputs[0];
    const link = h('a', { href: `#${input.id}`, text: name });
    link.addEventListener('click', (event) => {
      event.preventDefault();
      input.scrollIntoView({ block: 'center' });
      input.focus({ preventScroll: true });
    });
    status.append(i ? ', ' : '', link);
  });
}
