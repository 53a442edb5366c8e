// The tuner's assets: drop a mesh (POST /v1/meshes, then mesh=<id>), choose an
// environment, and download the image, a turntable (POST /v1/turntables, its progress
// polled) and the exports (GLSL, .glb), each through the one request wrapper.
import { postJSON, problemOf, request } from './api.js';
import { $, save, sleep } from './dom.js';
import { renderQuery } from './queries.js';
import { imageFileName } from './share.js';
import { changedFields, defaultOf, setValue, state } from './state.js';

const POLL_MS = 300;

const say = (where, text) => { $(where).textContent = text; };
const body = () => ({ preset: state.preset, ...changedFields() });
const busyIn = (where, what) => ({ wait }) => say(where, `${what}: the service is busy; trying again in ${wait} s…`);
const problem = async (resp) => (await problemOf(resp)).lines.join('; ');

async function upload(file) {
  if (!file) return;
  say('#mesh-status', `Uploading ${file.name} (${Math.round(file.size / 1024)} KB)…`);
  const resp = await request('/v1/meshes', { method: 'POST', body: file,
    headers: { 'Content-Type': 'application/octet-stream' }, onBusy: busyIn('#mesh-status', file.name) });
  if (!resp.ok) {
    say('#mesh-status', `${file.name}: ${await problem(resp)}`);
    return;
  }
  const info = await resp.json();
  say('#mesh-status', `${file.name}: ${info.format.toUpperCase()}, ${info.triangles} ` +
    `triangles, tangents ${info.tangents === 'uv' ? 'from its UVs' : info.tangents}`);
  setValue('mesh', info.id, 'upload');
}

function setupDrop() {
  const zone = $('#dropzone');
  const input = $('#mesh-file');
  zone.addEventListener('click', () => input.click());
  zone.addEventListener('keydown', (event) => {
    if (event.key === 'Enter' || event.key === ' ') { event.preventDefault(); input.click(); }
  });
  input.addEventListener('change', () => upload(input.files[0]));
  for (const kind of ['dragenter', 'dragover']) {
    zone.addEventListener(kind, (event) => { event.preventDefault(); zone.classList.add('over'); });
  }
  for (const kind of ['dragleave', 'drop']) {
    zone.addEventListener(kind, () => zone.classList.remove('over'));
  }
  zone.addEventListener('drop', (event) => {
    event.preventDefault();
    upload(event.dataTransfer.files[0]);
  });
}

// Poll a running turntable, its progress on the bar, until it is done or failed.
async function finished(status) {
  const bar = $('#tt-progress');
  bar.max = status.frames;
  bar.hidden = false;
  while (status.state === 'running') {
    bar.value = status.done;
    say('#asset-status', `Turntable: ${status.done} of ${status.frames} frames…`);
    await sleep(POLL_MS);
    status = await (await request(`/v1/turntables/${status.id}`)).json();
  }
  bar.hidden = true;
  return status;
}

async function turntable() {
  const frames = Number($('#tt-frames').value) || 36;
  const animation = $('#tt-format').value;
  const resp = await postJSON('/v1/turntables', { ...body(), frames, animation },
    { onBusy: busyIn('#asset-status', 'Turntable') });
  if (!resp.ok) { say('#asset-status', `Turntable: ${await problem(resp)}`); return; }
  const status = await finished(await resp.json());
  if (status.state !== 'done') { say('#asset-status', `Turntable failed: ${status.error}`); return; }
  const result = await request(status.result);
  if (!result.ok) { say('#asset-status', `Turntable: ${await problem(result)}`); return; }
  save(await result.blob(), `opaline-turntable.${animation}`);
  say('#asset-status', `Turntable: ${status.frames} frames, downloaded`);
}

// A download: the answer of `ask()` saved as `name` (or the name `name(resp)` gives it),
// or its problem shown as `what`'s.
async function download(what, ask, name) {
  const resp = await ask();
  if (!resp.ok) { say('#asset-status', `${what}: ${await problem(resp)}`); return; }
  save(await resp.blob(), typeof name === 'function' ? name(resp) : name);
}

export function setupAssets() {
  setupDrop();
  // "none" is the preset's own lights: an override only where the preset's default is a
  // map (soap-bubble's studio), else the default itself.
  $('#env-pick').addEventListener('change', (event) => {
    const value = event.target.value;
    const none = value === 'none' && [null, undefined, 'none'].includes(defaultOf('environment'));
    setValue('environment', none ? null : value, 'picker');
  });
  // A link (to copy or open), but a click fetches it: a link cannot carry the API key.
  $('#dl-image').addEventListener('click', (event) => {
    event.preventDefault();
    const url = `/v1/render?${renderQuery()}`;
    event.currentTarget.href = url;
    download('Image', () => request(url),
      (resp) => imageFileName(state.preset, resp.headers.get('content-type')));
  });
  $('#dl-glsl').addEventListener('click', () => download('GLSL',
    () => request(`/v1/export/glsl?${renderQuery()}`), 'opaline.glsl'));
  $('#dl-glb').addEventListener('click', () => download('glTF',
    () => postJSON('/v1/export/glb', body()), `${state.preset}.glb`));
  $('#dl-turntable').addEventListener('click', turntable);
}
