// One control per field kind (number, choice, switch, text), built from its spec: each
// returns { wrap, desc, err, reset, inputs, show(value, source) }.
import { h } from './dom.js';
import { scaleOf, STEPS } from './scale.js';
import { defaultOf, isTier, LIGHT_FALLBACK, setInvalid, setValue, state, tierValue } from './state.js';

export function fieldShell(spec, labelFor) {
  const name = spec.name;
  const reset = h('button', {
    type: 'button', class: 'reset', title: `Reset ${name} to the preset's value`,
    'aria-label': `Reset ${name} to the preset's value`, text: '↺',
  });
  reset.addEventListener('click', () => {
    setValue(name, null, null);
    // The button hides itself: keep the keyboard focus in the field.
    const first = state.controls.get(name)?.inputs[0];
    if (first) first.focus();
  });
  const head = h('div', { class: 'field-head' },
    h('label', { for: labelFor, text: name }),
    h('span', { class: 'note', id: `note-${name}` }), reset);
  const wrap = h('div', { class: 'field', 'data-field': name }, head);
  const desc = h('p', { class: 'desc', id: `desc-${name}`, text: spec.description });
  const err = h('p', { class: 'error', id: `err-${name}`, role: 'alert', hidden: true });
  return { wrap, desc, err, reset };
}

export function numberInput(id, range, label, described) {
  return h('input', {
    type: 'number', id, inputmode: 'decimal', step: 'any', 'aria-label': label,
    min: range.minOpen ? null : range.min, max: range.maxOpen ? null : range.max,
    'aria-describedby': described,
  });
}

function slider(spec, scale) {
  const name = spec.name;
  const node = h('input', {
    type: 'range', id: `rng-${name}`, min: 0, max: STEPS, step: 1,
    'aria-label': `${name} slider`, 'aria-describedby': `desc-${name}`,
  });
  node.addEventListener('input', () => setValue(name, scale.toValue(Number(node.value)), node));
  return node;
}

function onNumberInput(name, input) {
  if (input.value.trim() === '' && defaultOf(name) === null) {
    setValue(name, null, input);
  } else if (input.validity.badInput || input.value.trim() === '') {
    setInvalid(name, `${name}: enter a number`);
  } else {
    setValue(name, Number(input.value), input);
  }
}

// A number: slider and number field, kept in step.
export function numberControl(spec) {
  const name = spec.name;
  const shell = fieldShell(spec, `in-${name}`);
  const input = numberInput(`in-${name}`, spec, null, `desc-${name} err-${name}`);
  if (spec.integer) input.setAttribute('inputmode', 'numeric');
  const scale = scaleOf(spec);
  const range = scale ? slider(spec, scale) : null;
  input.addEventListener('input', () => onNumberInput(name, input));
  shell.wrap.append(h('div', { class: 'inputs' }, range, input), shell.desc, shell.err);
  return {
    ...shell,
    inputs: [input, range].filter(Boolean),
    show(value, source) {
      const blank = value === null || value === undefined;
      if (source !== input) input.value = blank ? '' : String(value);
      input.placeholder = blank ? (isTier(name) ? 'tier' : 'preset') : '';
      const tier = blank && isTier(name) ? tierValue(name) : undefined;
      input.title = tier === undefined ? '' : `the tier's value: ${tier}`;
      // An unset tier field's slider stands at the tier's value, not at its range's end.
      const tierNumber = typeof tier === 'number' ? tier : undefined;
      if (range && source !== range) {
        const shown = blank ? (tierNumber ?? LIGHT_FALLBACK[name] ?? spec.min) : value;
        range.value = String(Math.round(scale.toPos(Number(shown))));
      }
      const unsetText = tierNumber === undefined ? 'preset value' : `tier's value: ${tierNumber}`;
      if (range) range.setAttribute('aria-valuetext', blank ? unsetText : String(value));
      shell.wrap.classList.toggle('unset', blank);
    },
  };
}

export function enumControl(spec) {
  const name = spec.name;
  const shell = fieldShell(spec, `in-${name}`);
  const select = h('select', { id: `in-${name}`, 'aria-describedby': `desc-${name} err-${name}` });
  if (isTier(name)) select.append(h('option', { value: '', text: "tier's value" }));
  for (const option of spec.options) select.append(h('option', { value: option, text: option }));
  select.addEventListener('change', () => setValue(name, select.value || null, select));
  shell.wrap.append(h('div', { class: 'inputs' }, select), shell.desc, shell.err);
  return { ...shell, inputs: [select], show: (value) => { select.value = value ?? ''; } };
}

export function boolControl(spec) {
  const name = spec.name;
  const shell = fieldShell(spec, `in-${name}`);
  const box = h('input', { type: 'checkbox', id: `in-${name}`,
    'aria-describedby': `desc-${name} err-${name}` });
  box.addEventListener('change', () => setValue(name, box.checked, box));
  shell.wrap.classList.add('bool');
  shell.wrap.firstChild.prepend(box);
  shell.wrap.append(shell.desc, shell.err);
  return { ...shell, inputs: [box], show: (value) => { box.checked = Boolean(value); } };
}

export function textControl(spec) {
  const name = spec.name;
  const shell = fieldShell(spec, `in-${name}`);
  const input = h('input', { type: 'text', id: `in-${name}`,
    'aria-describedby': `desc-${name} err-${name}` });
  input.addEventListener('input', () => setValue(name, input.value.trim() || null, input));
  shell.wrap.append(h('div', { class: 'inputs' }, input), shell.desc, shell.err);
  return { ...shell, inputs: [input], show(value, source) {
    if (source !== input) input.value = value ?? '';
  } };
}
