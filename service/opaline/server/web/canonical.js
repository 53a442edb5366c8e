// The preview's URLs spelled as the service spells them (pipeline/canonical.py, the
// Content-Location of every answer, less its rev): a shared cache in front of the
// replicas keys on the URL, so a page that spelled one image its own way would miss
// what the batch client, another tab or another user already had rendered.
// Fields in one fixed order (preset, the request-only fields, quality, then the
// schema's), those equal to what the preset and the tier give dropped, numbers as
// Python's repr writes them. rev (the image's content key, a hash of the resolved job,
// the scene and the shader sources) is the service's alone, so the page's URL is cached
// for cache_max_age_s rather than for good. quality=auto's pick is the service's too:
// with it the tier's own values cannot be dropped, and the URL is the service's only
// where the pick is the preset's tier.
// tests/web/test_web_canonical.py checks the spelling against the service's.
import { same } from './dom.js';
import { state, TIER_MATERIAL, tierSetting } from './state.js';

// pipeline/canonical.py REQUEST_ONLY: the fields a job does not keep, right after the preset.
export const REQUEST_ONLY = ['mesh', 'tangent_field', 'tangent_axis', 'mesh_up', 'max_flip',
  'max_delta_e'];
// model/tiers.py render_settings: what a tier sets unless the preset sets its own.
export const TIER_SETTINGS = ['samples', 'wavelengths', 'aa'];

// Python's repr of a float: the shortest digits that read back (as JS has them), in
// fixed notation for exponents -4 … 15, else d.ddde±XX.
function pythonFloat(x) {
  const [mantissa, exp] = x.toExponential().split('e');
  const e = Number(exp);
  const sign = x < 0 ? '-' : '';
  const digits = mantissa.replace('-', '').replace('.', '');
  if (e < -4 || e >= 16) {
    const m = digits.length > 1 ? `${digits[0]}.${digits.slice(1)}` : digits;
    return `${sign}${m}e${e < 0 ? '-' : '+'}${String(Math.abs(e)).padStart(2, '0')}`;
  }
  if (e < 0) return `${sign}0.${'0'.repeat(-e - 1)}${digits}`;
  return `${sign}${digits.slice(0, e + 1).padEnd(e + 1, '0')}.${digits.slice(e + 1) || '0'}`;
}

// pipeline/canonical.py spell: integral numbers as integers (1, 1.0 and 1e0 are one
// exposure), tuples comma-separated.
export function spell(value) {
  if (Array.isArray(value)) return value.map(spell).join(',');
  if (typeof value === 'boolean') return value ? 'true' : 'false';
  if (typeof value === 'number' && Number.isFinite(value)) {
    return Number.isInteger(value) && Math.abs(value) < 1e15 ? String(value) : pythonFloat(value);
  }
  return String(value);
}

// urllib.parse.urlencode(…, safe=','): space as +, only letters, digits, _.-~ and , bare.
const encode = (text) => encodeURIComponent(text)
  .replace(/[!'()*]/g, (c) => `%${c.charCodeAt(0).toString(16).toUpperCase()}`)
  .replace(/%20/g, '+').replace(/%2C/g, ',');

// What the job draws for `name` when the request leaves it out: the preset's value, or
// for a tier setting the tier's (undefined under quality=auto: only the service knows).
function baseOf(name, info, tier, fields) {
  if (name in info.resolved.material) return info.resolved.material[name];
  if (TIER_SETTINGS.includes(name)) {
    if (name in info.defaults) return info.defaults[name];
    const material = { ...info.resolved.material };
    for (const key of TIER_MATERIAL) if (key in fields) material[key] = fields[key];
    return tierSetting(name, tier, material);
  }
  return info.resolved[name] ?? null;
}

// The canonical query (without rev) of a request on `preset` giving `fields`; `info` is
// the preset's GET /v1/presets/{name}.
export function canonicalQuery(preset, fields, info = state.info) {
  const parts = [];
  const add = (name, value) => parts.push(`${encode(name)}=${encode(spell(value))}`);
  if (preset !== state.presetDefault) add('preset', preset);
  for (const name of REQUEST_ONLY) if (name in fields) add(name, fields[name]);
  const budget = 'max_flip' in fields || 'max_delta_e' in fields;
  const quality = fields.quality ?? (budget ? 'auto' : info.resolved.quality);
  if (quality !== info.resolved.quality) add('quality', quality);
  const tier = state.tiers.get(quality);
  for (const name of state.order) {
    if (name === 'quality' || REQUEST_ONLY.includes(name) || !(name in fields)) continue;
    if (!same(fields[name], baseOf(name, info, tier, fields))) add(name, fields[name]);
  }
  return parts.join('&');
}
