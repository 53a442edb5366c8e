// Opaline's material tuner: controls built from the service's OpenAPI schema, a live
// preview and MDF plot fetched from the API, and the same state copied as a JSON body, a
// curl command, a CLI command or a link to this page. This module wires the others.
import { getJSON } from './api.js';
import { setupAssets } from './assets.js';
import { buildControls, refreshAll, refreshField, refreshInactive } from './controls.js';
import { $, h, same } from './dom.js';
import { clearErrors, setStatus, showError } from './errors.js';
import { setupLightPad } from './lightpad.js';
import { endLive, schedule, startLive } from './preview.js';
import { readSchema } from './schema.js';
import { copySelected, overridesFromUrl, showCopy } from './share.js';
import { defaultOf, hooks, isMaterial, state } from './state.js';

Object.assign(hooks, { refreshField, refreshInactive, schedule });

function presetFailed(err) {
  clearErrors();
  showError(err.status === 404 ? 'preset' : 'general', [err.message]);
  $('#preset').value = state.preset || '';
  document.body.dataset.busy = 'false';
  return false;
}

async function choosePreset(name, overrides) {
  document.body.dataset.busy = 'true';
  let info;
  try {
    info = await getJSON(`/v1/presets/${encodeURIComponent(name)}`);
  } catch (err) {
    return presetFailed(err);
  }
  // Material changes belong to the old preset; size, light and output stay.
  const kept = overrides ?? Object.fromEntries(
    Object.entries(state.overrides).filter(([field]) => !isMaterial(field)));
  Object.assign(state, { preset: name, info, overrides: {} });
  state.invalid.clear();
  $('#preset').value = name;
  $('#preset-desc').textContent = `${info.description} ${info.figure ? `(${info.figure})` : ''}`;
  for (const [field, value] of Object.entries(kept)) {
    if (!same(value, defaultOf(field))) state.overrides[field] = value;
  }
  refreshAll();
  schedule(0);
  return true;
}

function wire() {
  const picker = $('#preset');
  picker.addEventListener('change', () => {
    state.presetError = null;
    choosePreset(picker.value, null);
  });
  $('#reset-all').addEventListener('click', () => {
    state.overrides = {};
    state.invalid.clear();
    refreshAll();
    schedule(0);
  });
  for (const radio of document.querySelectorAll('input[name="copy-kind"]')) {
    radio.addEventListener('change', showCopy);
  }
  $('#copy-button').addEventListener('click', copySelected);
  $('#controls').addEventListener('submit', (event) => event.preventDefault());
  setupLightPad();
  // A drag is live from the press on the light pad or a slider to the release.
  document.addEventListener('pointerdown', (event) => {
    if (event.button === 0 && event.target.closest('#stage, input[type="range"]')) startLive();
  }, true);
  for (const kind of ['pointerup', 'pointercancel']) document.addEventListener(kind, endLive, true);
}

async function load() {
  try {
    const [openapi, presets, tiers] = await Promise.all(
      [getJSON('/openapi.json'), getJSON('/v1/presets'), getJSON('/v1/tiers')]);
    state.tiers = new Map(tiers.map((tier) => [tier.name, tier]));
    state.presets = presets;
    return openapi;
  } catch (err) {
    showError('general', [`Cannot load the API description: ${err.message}`]);
    setStatus('');
    document.body.dataset.busy = 'false';
    return null;
  }
}

async function start() {
  setupAssets();
  const openapi = await load();
  if (!openapi) return;
  const schema = readSchema(openapi);
  Object.assign(state, { specs: schema.specs, order: schema.order, groups: schema.groups,
    presetDefault: schema.presetDefault });
  buildControls();
  for (const preset of state.presets) {
    $('#preset').append(h('option', { value: preset.name, text: preset.name }));
  }
  wire();
  const names = state.presets.map((p) => p.name);
  const fallback = names.includes(schema.presetDefault) ? schema.presetDefault : names[0];
  const query = new URLSearchParams(location.search);
  const wanted = query.get('preset') || fallback;
  if (!(await choosePreset(wanted, overridesFromUrl(query))) && wanted !== names[0]) {
    state.presetError = $('#err-preset').textContent;
    await choosePreset(fallback, {});
  }
}

start();
