// The tuner's assets: drop a mesh (POST /v1/meshes, then mesh=<id>), choose an
// environment, and download the image, a turntable (POST /v1/turntables, its
// progress polled) and the exports (GLSL, .glb). State lives in app.js; this
// file reaches it through window.opaline.
'use strict';

(() => {
  const $ = (sel) => document.querySelector(sel);
  const POLL_MS = 300;

  function say(where, text) { $(where).textContent = text; }

  function body() {
    return { preset: window.opaline.preset(), ...window.opaline.changedFields() };
  }

  function save(blob, name) {
    const link = document.createElement('a');
    link.href = URL.createObjectURL(blob);
    link.download = name;
    document.body.append(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  }

  async function problem(resp) {
    try {
      const detail = (await resp.json()).detail;
      return Array.isArray(detail) ? detail.join('; ') : String(detail);
    } catch { return `${resp.status} ${resp.statusText}`; }
  }

  async function upload(file) {
    if (!file) return;
    say('#mesh-status', `Uploading ${file.name} (${Math.round(file.size / 1024)} KB)…`);
    const resp = await fetch('/v1/meshes', { method: 'POST', body: file,
      headers: { 'Content-Type': 'application/octet-stream' } });
    if (!resp.ok) {
      say('#mesh-status', `${file.name}: ${await problem(resp)}`);
      return;
    }
    const info = await resp.json();
    say('#mesh-status', `${file.name}: ${info.format.toUpperCase()}, ${info.triangles} ` +
      `triangles, tangents ${info.tangents === 'uv' ? 'from its UVs' : info.tangents}`);
    window.opaline.setValue('mesh', info.id, 'upload');
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

  async function turntable() {
    const frames = Number($('#tt-frames').value) || 36;
    const animation = $('#tt-format').value;
    const bar = $('#tt-progress');
    let resp = await fetch('/v1/turntables', { method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify({ ...body(), frames, animation }) });
    if (!resp.ok) { say('#asset-status', `Turntable: ${await problem(resp)}`); return; }
    let status = await resp.json();
    bar.max = status.frames;
    bar.hidden = false;
    while (status.state === 'running') {
      bar.value = status.done;
      say('#asset-status', `Turntable: ${status.done} of ${status.frames} frames…`);
      await new Promise((done) => setTimeout(done, POLL_MS));
      status = await (await fetch(`/v1/turntables/${status.id}`)).json();
    }
    bar.hidden = true;
    if (status.state !== 'done') { say('#asset-status', `Turntable failed: ${status.error}`); return; }
    resp = await fetch(status.result);
    save(await resp.blob(), `opaline-turntable.${animation}`);
    say('#asset-status', `Turntable: ${status.frames} frames, downloaded`);
  }

  async function glb() {
    const resp = await fetch('/v1/export/glb', { method: 'POST',
      headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body()) });
    if (!resp.ok) { say('#asset-status', `glTF: ${await problem(resp)}`); return; }
    save(await resp.blob(), `${window.opaline.preset()}.glb`);
  }

  function start() {
    if (!window.opaline) return;
    setupDrop();
    $('#env-pick').addEventListener('change', (event) => {
      window.opaline.setValue('environment', event.target.value || null, 'picker');
    });
    $('#dl-image').addEventListener('click', (event) => {
      const query = window.opaline.renderQuery(false);
      event.currentTarget.href = `/v1/render?${query}`;
      event.currentTarget.download = `${window.opaline.preset()}.png`;
    });
    $('#dl-glsl').addEventListener('click', async () => {
      const resp = await fetch(`/v1/export/glsl?${window.opaline.renderQuery(false)}`);
      if (!resp.ok) { say('#asset-status', `GLSL: ${await problem(resp)}`); return; }
      save(await resp.blob(), 'opaline.glsl');
    });
    $('#dl-glb').addEventListener('click', glb);
    $('#dl-turntable').addEventListener('click', turntable);
  }

  window.addEventListener('DOMContentLoaded', start);
})();
