// The query strings the page asks for: the render (as the link and downloads carry it),
// the MDF plot, and the live drafts shown while a hand drags.
import { $, clamp, fmt } from './dom.js';
import { changedFields, isTier, state, valueOf } from './state.js';

const MDF_PLOT_SIZE = 256;
// The MDF plot shows D only: these are the material fields it reads.
const MDF_PLOT_FIELDS = ['mdf', 'ex', 'ey', 'mu_f', 'alpha', 'beta', 'theta1', 'theta2'];

export function renderQuery(forPreview) {
  const query = new URLSearchParams({ preset: state.preset });
  for (const [name, value] of Object.entries(changedFields())) {
    // A browser cannot show .npy: the preview is the PNG of the same render.
    if (forPreview && name === 'format' && value === 'npy') continue;
    query.set(name, fmt(value));
  }
  return query;
}

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

// Drafts are drawn at the preview's displayed size × devicePixelRatio and negotiated
// (format=auto: WebP in browsers that take it), at the draft tier's own settings.
export function liveQuery() {
  const query = renderQuery(true);
  const job = state.info.resolved;
  const w = valueOf('width') ?? job.width;
  const hgt = valueOf('height') ?? job.height;
  const shown = $('#preview').getBoundingClientRect().width || w;
  const width = clamp(Math.round(shown * (window.devicePixelRatio || 1)), 16, 2048);
  const height = clamp(Math.round((width * hgt) / w), 16, 2048);
  for (const name of state.order) if (isTier(name)) query.delete(name);
  query.set('quality', 'draft');
  query.set('format', 'auto');
  query.set('width', String(width));
  query.set('height', String(height));
  return query;
}
