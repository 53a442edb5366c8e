// A text field whose schema lists its usual values (`examples`: the built-in
// environments): a choice of those, of the preset's own (no value), or of a name typed
// in (an environment file of the service's folder).
import { h } from './dom.js';
import { fieldShell } from './inputs.js';
import { setValue } from './state.js';

const TYPED = '\u0000typed';  // the choice that shows the text box

export function pickControl(spec) {
  const name = spec.name;
  const shell = fieldShell(spec, `in-${name}`);
  const select = h('select', { id: `in-${name}`, 'aria-describedby': `desc-${name} err-${name}` });
  select.append(h('option', { value: '', text: "preset's" }));
  for (const option of spec.examples) select.append(h('option', { value: option, text: option }));
  select.append(h('option', { value: TYPED, text: 'file…' }));
  const text = h('input', { type: 'text', id: `in-${name}-file`, class: 'pick-file',
    'aria-label': `${name} file name`, placeholder: 'name.hdr', hidden: true,
    'aria-describedby': `desc-${name} err-${name}` });
  select.addEventListener('change', () => {
    if (select.value !== TYPED) setValue(name, select.value || null, select);
    else {
      setValue(name, text.value.trim() || null, select);
      text.focus();
    }
  });
  text.addEventListener('input', () => setValue(name, text.value.trim() || null, text));
  shell.wrap.append(h('div', { class: 'inputs' }, select, text), shell.desc, shell.err);
  return { ...shell, inputs: [select, text], show(value, source) {
    const listed = value === null || value === undefined || spec.examples.includes(value);
    // While a name is being typed (or the file choice was just made) the choice stays.
    if (source !== text && source !== select) select.value = listed ? (value ?? '') : TYPED;
    if (source !== text && !listed) text.value = value;
    text.hidden = select.value !== TYPED;
  } };
}
