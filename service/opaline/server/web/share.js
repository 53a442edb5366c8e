// The state copied as a JSON body, a curl command, a CLI command or a link to this page,
// and that link's query read back into the state.
import { hasKey } from './api.js';
import { $, fmt, shellQuote } from './dom.js';
import { renderQuery } from './queries.js';
import { changedFields, state, valueOf } from './state.js';

// The file name each format is saved under (the schema lists formats, not their files).
const EXTENSIONS = { png: '.png', png16: '.png', npy: '.npy', webp: '.webp',
  'webp-lossless': '.webp', avif: '.avif', jpeg: '.jpg' };
// The same by the media type an answer has (format=auto's choice is the service's).
const BY_TYPE = { 'image/png': '.png', 'image/webp': '.webp', 'image/avif': '.avif',
  'image/jpeg': '.jpg', 'application/x-npy': '.npy' };
export const imageFileName = (preset, type) =>
  preset + (BY_TYPE[(type || '').split(';')[0].trim()] || '.png');
const BOOLEANS = new Map([['true', true], ['1', true], ['false', false], ['0', false]]);

function pageUrl() {
  const url = new URL(location.href);
  url.search = renderQuery().toString();
  url.hash = '';
  return url.toString();
}

export function writeOutputs() {
  if (!state.preset) return;
  const fields = changedFields();
  const body = { preset: state.preset, ...fields };
  const file = state.preset + (EXTENSIONS[valueOf('format')] || '.png');
  const endpoint = new URL('/v1/render', location.href).toString();
  $('#copy-json').value = JSON.stringify(body, null, 2);
  const keyArgs = hasKey() ? ['-H', '"X-API-Key: $OPALINE_API_KEY"'] : [];
  $('#copy-curl').value = ['curl', '-fsS', shellQuote(endpoint), ...keyArgs,
    '-H', shellQuote('Content-Type: application/json'),
    '-d', shellQuote(JSON.stringify(body)), '-o', shellQuote(file)].join(' ');
  $('#copy-cli').value = cliCommand(fields, file);
  const link = pageUrl();
  $('#copy-url').value = link;
  if (link !== location.href) history.replaceState(null, '', link);
}

function cliCommand(fields, file) {
  const args = ['opaline', 'render', shellQuote(state.preset)];
  const rest = { ...fields };
  if ('width' in rest || 'height' in rest) {
    args.push('--size', `${valueOf('width')}x${valueOf('height')}`);
    delete rest.width;
    delete rest.height;
  }
  for (const option of ['quality', 'format']) {
    if (option in rest) args.push(`--${option}`, shellQuote(fmt(rest[option])));
    delete rest[option];
  }
  if (rest.transparent === true) {
    args.push('--transparent');
    delete rest.transparent;
  }
  for (const [name, value] of Object.entries(rest)) {
    args.push('--set', shellQuote(`${name}=${fmt(value)}`));
  }
  args.push('-o', shellQuote(file));
  return args.join(' ');
}

const selectedCopy = () => $('input[name="copy-kind"]:checked').value;

export function showCopy() {
  const kind = selectedCopy();
  for (const area of document.querySelectorAll('.copy-text')) {
    area.hidden = area.id !== `copy-${kind}`;
  }
  $('#copy-done').textContent = '';
}

export async function copySelected() {
  const area = $(`#copy-${selectedCopy()}`);
  try {
    await navigator.clipboard.writeText(area.value);
  } catch {
    area.focus();
    area.select(); // no clipboard API (plain http): select it for Ctrl+C
    if (!document.execCommand || !document.execCommand('copy')) {
      $('#copy-done').textContent = 'Selected: press Ctrl+C';
      return;
    }
  }
  $('#copy-done').textContent = 'Copied';
}

// The page's query string is the render's: parse it back into overrides.
function parseValue(spec, text) {
  if (spec.kind === 'number') {
    const value = Number(text);
    return text.trim() !== '' && Number.isFinite(value) ? value : undefined;
  }
  if (spec.kind === 'vector') {
    const value = text.split(',').map(Number);
    return value.length === spec.items.length && value.every(Number.isFinite) ? value : undefined;
  }
  if (spec.kind === 'bool') return BOOLEANS.get(text);
  if (spec.kind === 'enum') return spec.options.includes(text) ? text : undefined;
  return text;
}

export function overridesFromUrl(query) {
  const overrides = {};
  for (const [name, text] of query) {
    const spec = state.specs.get(name);
    const value = spec && parseValue(spec, text);
    if (value !== undefined) overrides[name] = value;
  }
  return overrides;
}
