// The page's state: the preset plus the fields the user changed from the preset's values
// (GET /v1/presets/{name}); only those are sent, so the browser and the service cache
// every repeated view. Other modules react to a change through `hooks`, set by main.js.
import { same } from './dom.js';

export const state = {
  specs: new Map(),      // field name → spec read from the schema
  order: [],             // field names in schema order (stable URLs)
  groups: [],            // [{id, title, fields}] in page order
  tiers: new Map(),      // tier name → its values (GET /v1/tiers)
  presets: [],
  preset: null,
  info: null,            // GET /v1/presets/{name}
  overrides: {},         // field → value the user changed
  invalid: new Map(),    // field → local message (not a number yet)
  controls: new Map(),   // field → control
  presetError: null,     // a preset named in the link that the service does not know
  presetDefault: null,   // the preset a request naming none draws (the schema's default)
};

export const hooks = { refreshField: () => {}, refreshInactive: () => {}, schedule: () => {} };

export const LIGHT = { azimuth: 'light_azimuth', elevation: 'light_elevation' };
// Where a drag starts while the preset's key light direction is not known.
export const LIGHT_FALLBACK = { light_azimuth: 0, light_elevation: 45 };

export const isTier = (name) => state.specs.get(name)?.tier === true;
// A material field: its preset value is in the resolved job's material.
export const isMaterial = (name) => Boolean(state.info && name in state.info.resolved.material);

export function defaultOf(name) {
  const info = state.info;
  if (!info) return null;
  if (name in LIGHT_FALLBACK) {
    // The API's `key_light` (where the preset puts its light), when it gives one.
    const key = info.key_light && info.key_light[name.replace('light_', '')];
    return typeof key === 'number' ? key : null;
  }
  if (isTier(name)) return info.defaults[name] ?? null;
  if (isMaterial(name)) return info.resolved.material[name] ?? null;
  return info.resolved[name] ?? null;
}

export const valueOf = (name) => (name in state.overrides ? state.overrides[name] : defaultOf(name));

// What the chosen quality tier sets for a tier field, when the tier is a named one.
// model/tiers.py Tier.wavelengths_for: a tier's wavelengths for the colour source drawn
// (a film's are its own: a stack's, else on a dielectric or on a metal).
export function tierSetting(name, tier, material) {
  if (tier === undefined || name !== 'wavelengths' || material.iridescence !== 'thin-film') {
    return tier?.[name];
  }
  if (material.film_stack_pairs > 0) return tier.stack_wavelengths;
  return material.substrate === 'conductor' ? tier.metal_film_wavelengths : tier.film_wavelengths;
}

// The material fields tierSetting reads.
export const TIER_MATERIAL = ['iridescence', 'substrate', 'film_stack_pairs'];

export const tierValue = (name) => tierSetting(name, state.tiers.get(valueOf('quality')),
  Object.fromEntries(TIER_MATERIAL.map((key) => [key, valueOf(key)])));

// The fields sent: the user's changes, in schema order.
export function changedFields() {
  const fields = {};
  for (const name of state.order) if (name in state.overrides) fields[name] = state.overrides[name];
  return fields;
}

export function setValue(name, value, source) {
  state.invalid.delete(name);
  if (value === null || value === '' || same(value, defaultOf(name))) delete state.overrides[name];
  else state.overrides[name] = value;
  hooks.refreshField(name, source);
  // The tier fields show what the chosen tier sets.
  if (name === 'quality') for (const spec of state.specs.values()) if (spec.tier) hooks.refreshField(spec.name, null);
  if ([...state.specs.values()].some((spec) => spec.applies && name in spec.applies)) {
    hooks.refreshInactive();
  }
  hooks.schedule();
}

export function setInvalid(name, message) {
  state.invalid.set(name, message);
  hooks.schedule();
}
