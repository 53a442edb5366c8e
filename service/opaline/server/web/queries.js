// The query strings the page asks for: the render (as the link and downloads carry it),
// the preview and the live drafts shown while a hand drags (both canonical, so a shared
// cache serves them: canonical.js), and the MDF plot.
import { canonicalQuery } from './canonical.js';
import { $, clamp, fmt } from './dom.js';
import { changedFields, isTier, state, valueOf } from './state.js';

const MDF_PLOT_SIZE = 256;
// The MDF plot shows D only: these are the material fields it reads.
const MDF_PLOT_FIELDS = ['mdf', 'ex', 'ey', 'mu_f', 'alpha', 'beta', 'theta1', 'theta2'];

export function renderQuery() {
  const query = new URLSearchParams({ preset: state.preset });
  for (const [name, value] of Object.entries(changedFields())) query.set(name, fmt(value));
  return query;
}

// The fields the preview asks for. A browser cannot show .npy: the preview is the PNG of
// the same render.
function previewFields() {
  const fields = changedFields();
  if (fields.format === 'npy') delete fields.format;
  return fields;
}

export const previewQuery = () => canonicalQuery(state.preset, previewFields());

export function mdfQuery() {
  // /v1/mdf knows no presets: it gets every field its plot reads.
  const query = new URLSearchParams();
  for (const name of MDF_PLOT_FIELDS) {
    const value = valueOf(name);
    if (value !== null && state.specs.has(name)) query.set(name, fmt(value));
  }
  if ('wavelengths' in state.overrides) query.set('wavelengths', fmt(state.overrides.wavelengths));
  query.set('size', String(MDF_PLOT_SIZE));
  return query;
}

// Drafts are drawn at the preview's displayed size × devicePixelRatio, at the draft
// tier's own settings, as PNG: what format=auto gave them (fetch sends Accept: */*), but
// named, since the canonical URL names the format an answer has.
export function liveQuery() {
  const fields = previewFields();
  const job = state.info.resolved;
  const w = valueOf('width') ?? job.width;
  const hgt = valueOf('height') ?? job.height;
  const shown = $('#preview').getBoundingClientRect().width || w;
  const width = clamp(Math.round(shown * (window.devicePixelRatio || 1)), 16, 2048);
  const height = clamp(Math.round((width * hgt) / w), 16, 2048);
  for (const name of state.order) if (isTier(name)) delete fields[name];
  Object.assign(fields, { quality: 'draft', format: 'png', width, height });
  return canonicalQuery(state.preset, fields);
}
