// A colour field (a linear RGB triple): three number fields and a colour picker.
import { clamp, h } from './dom.js';
import { fieldShell, numberInput } from './inputs.js';
import { setInvalid, setValue } from './state.js';

// Linear RGB ↔ the sRGB hex of <input type=color>.
const toSrgb = (c) => (c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055);
const toLinear = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);

function hexOf(rgb) {
  return '#' + rgb.map((c) => Math.round(clamp(toSrgb(clamp(c, 0, 1)), 0, 1) * 255)
    .toString(16).padStart(2, '0')).join('');
}

function linearOf(hex) {
  return [0, 2, 4].map((i) =>
    Number(toLinear(parseInt(hex.slice(1 + i, 3 + i), 16) / 255).toFixed(4)));
}

export function vectorControl(spec) {
  const name = spec.name;
  const shell = fieldShell(spec, `in-${name}-0`);
  // A colour (each item within 0 … 1) has a picker and R, G, B; a direction
  // (tangent_axis) has neither: X, Y, Z, empty while unset (its default is the service's).
  const isColour = spec.items.every((range) => range.min >= 0 && range.max <= 1);
  const names = isColour ? ['red', 'green', 'blue'] : ['x', 'y', 'z'];
  const inputs = spec.items.map((range, i) =>
    numberInput(`in-${name}-${i}`, range, `${name} ${names[i]}`, `desc-${name} err-${name}`));
  const color = isColour ? h('input', { type: 'color', id: `in-${name}-color`,
    'aria-label': `${name} colour picker (sRGB)`, 'aria-describedby': `desc-${name}` }) : null;
  const row = h('div', { class: 'inputs vector' }, color);
  inputs.forEach((input, i) => {
    row.append(h('label', { class: 'channel', for: input.id, text: (isColour ? 'RGB' : 'XYZ')[i] }),
      input);
    input.addEventListener('input', () => {
      const value = inputs.map((x) => Number(x.value));
      if (input.validity.badInput || input.value.trim() === '' || value.some((x) => !Number.isFinite(x))) {
        setInvalid(name, `${name}: enter three numbers`);
      } else setValue(name, value, input);
    });
  });
  if (color) color.addEventListener('input', () => setValue(name, linearOf(color.value), color));
  shell.wrap.append(row, shell.desc, shell.err);
  return {
    ...shell,
    inputs: color ? [...inputs, color] : inputs,
    show(value, source) {
      const shown = value || (isColour ? [0, 0, 0] : ['', '', '']);
      inputs.forEach((input, i) => { if (source !== input) input.value = String(shown[i]); });
      if (color && source !== color) color.value = hexOf(value || [0, 0, 0]);
    },
  };
}
