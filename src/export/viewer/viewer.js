// fbakit viewer: shows the embedded glb, plays its `play` animation looping, and poses the face
// from FAP sliders. The data it reads (#fbakit-data) is described by `ViewerModel` in
// src/export/viewer.rs; the posing rules are in that module's docs.
(function () {
  'use strict';

  const T = window.FBAKIT_THREE;
  const $ = (id) => document.getElementById(id);
  const model = JSON.parse($('fbakit-data').textContent);

  // Feature-point colours by group (2 and 8 are the lips, 3 and 4 the eyes and brows).
  const GROUP_COLORS = {
    2: 0xf0a24a, 3: 0x5fb3d9, 4: 0x8fd16a, 5: 0xd98ad9, 6: 0xe05a5a,
    7: 0xcccccc, 8: 0xffc864, 9: 0xa0e0d0, 10: 0xb0a0ff, 11: 0xe0e0a0,
  };

  const canvas = $('view');
  const stage = $('stage');
  const renderer = new T.WebGLRenderer({
    canvas,
    antialias: true,
    alpha: true,
    // Keeps the last frame readable (screenshots, the browser test).
    preserveDrawingBuffer: true,
  });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.outputColorSpace = T.SRGBColorSpace;

  const scene = new T.Scene();
  const camera = new T.PerspectiveCamera(28, 1, 0.01, 1000);
  scene.add(new T.HemisphereLight(0xf4f1ee, 0x2a2e36, 0.9));
  const key = new T.DirectionalLight(0xfff6ec, 2.8);
  key.position.set(-0.7, 0.8, 1.0);
  const fill = new T.DirectionalLight(0xdfe8ff, 0.45);
  fill.position.set(0.8, 0.1, 0.6);
  const rim = new T.DirectionalLight(0xffffff, 0.9);
  rim.position.set(0.0, 0.8, -1.0);
  // Lights follow the camera so the face stays lit from the viewer's side while orbiting.
  camera.add(key, fill, rim);
  scene.add(camera);

  const controls = new T.OrbitControls(camera, canvas);
  controls.enableDamping = true;
  controls.dampingFactor = 0.12;

  const target = new T.Vector3().fromArray(model.camera.target);
  const radius = model.camera.radius;

  /** The rows of the canvas (CSS pixels from its top) not covered by the caption above or
   * the transport bar below: where the face is framed. */
  function freeBand() {
    const c = canvas.getBoundingClientRect();
    const h = Math.max(1, c.height);
    let top = 0;
    let bottom = h;
    const tr = $('transport');
    if (tr && !tr.hidden) bottom = Math.min(bottom, tr.getBoundingClientRect().top - c.top - 6);
    const cap = $('caption');
    if (cap) top = Math.max(top, cap.getBoundingClientRect().bottom - c.top);
    // A very small window keeps at least half its height for the face.
    if (bottom - top < h * 0.5) {
      top = 0;
      bottom = Math.max(bottom, h * 0.5);
    }
    return { top, bottom, height: h };
  }

  /** Shifts the image so that the view's centre is the middle of the free band. */
  function applyViewOffset() {
    const c = canvas.getBoundingClientRect();
    const w = Math.max(1, c.width);
    const band = freeBand();
    const shift = band.height / 2 - (band.top + band.bottom) / 2;
    if (Math.abs(shift) < 0.5) {
      camera.clearViewOffset();
    } else {
      camera.setViewOffset(w, band.height, 0, shift, w, band.height);
    }
  }

  function frameFace() {
    const vfov = T.MathUtils.degToRad(camera.fov);
    const hfov = 2 * Math.atan(Math.tan(vfov / 2) * camera.aspect);
    const [ex, ey, ez] = model.camera.half_extent;
    // Fit the face's x-y rectangle with a margin into the band above the controls, from in
    // front of its depth.
    const band = freeBand();
    const tanV = Math.tan(vfov / 2) * Math.max(0.2, (band.bottom - band.top) / band.height);
    const dist = 1.12 * Math.max(ey / tanV, ex / Math.tan(hfov / 2)) + ez;
    applyViewOffset();
    // A little from the side and above, so the face reads as 3D from the first frame.
    const yaw = T.MathUtils.degToRad(14);
    const pitch = T.MathUtils.degToRad(5);
    // Along the face's own axes: a face modelled facing -z is seen from its front too.
    const [right, up, front] = model.camera.axes.map((a) => new T.Vector3().fromArray(a));
    camera.up.copy(up);
    camera.position
      .copy(target)
      .addScaledVector(right, dist * Math.sin(yaw) * Math.cos(pitch))
      .addScaledVector(up, dist * Math.sin(pitch))
      .addScaledVector(front, dist * Math.cos(yaw) * Math.cos(pitch));
    camera.near = dist / 100;
    camera.far = dist * 20;
    camera.updateProjectionMatrix();
    controls.target.copy(target);
    controls.update();
  }

  function resize() {
    const w = Math.max(1, stage.clientWidth);
    const h = Math.max(1, stage.clientHeight);
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    applyViewOffset();
    camera.updateProjectionMatrix();
  }

  // ---- FAP values and posing ------------------------------------------------------------

  const values = {}; // key name -> current value
  const sliders = {}; // key name -> { input, output, row, unit }
  const tracks = {};
  for (const t of model.tracks) tracks[t.key] = t.values;
  const stream = model.stream;

  /** Signed length of [0, p] inside each interval, outer intervals extended to ±∞. */
  function intervalWeights(borders, p) {
    const n = borders.length - 1;
    const out = new Array(Math.max(n, 0)).fill(0);
    for (let j = 0; j < n; j++) {
      const lo = j === 0 ? -Infinity : borders[j];
      const hi = j + 1 === n ? Infinity : borders[j + 1];
      out[j] = p >= 0
        ? Math.max(Math.min(p, hi) - Math.max(lo, 0), 0)
        : -Math.max(Math.min(hi, 0) - Math.max(p, lo), 0);
    }
    return out;
  }

  const nodeObjects = new Map(); // glTF node index -> Object3D
  const meshObjects = new Map(); // glTF node index -> [Mesh] carrying its morph targets

  const qTmp = new T.Quaternion();
  const axisTmp = new T.Vector3();

  /** Poses the face from `values` with the FAT rules (see src/export/viewer.rs). */
  function applyPose() {
    for (const m of model.meshes) {
      const objs = meshObjects.get(m.node) || [];
      const w = m.targets.map((t) => {
        const p = values[t.key] || 0;
        if (p === 0 || !Number.isFinite(p)) return 0;
        return (intervalWeights(t.borders, p)[t.interval] || 0) / t.span;
      });
      for (const o of objs) {
        if (!o.morphTargetInfluences) continue;
        for (let i = 0; i < w.length; i++) o.morphTargetInfluences[i] = w[i];
      }
    }
    for (const r of model.transforms) {
      const o = nodeObjects.get(r.node);
      if (!o) continue;
      const dq = new T.Quaternion();
      const dt = new T.Vector3();
      const ds = new T.Vector3();
      for (const e of r.entries) {
        const p = values[e.key] || 0;
        if (p === 0 || !Number.isFinite(p)) continue;
        if (e.field === 'rotation') {
          qTmp.setFromAxisAngle(axisTmp.fromArray(e.axis), e.angle * p);
          dq.premultiply(qTmp);
        } else if (e.field === 'translation') {
          dt.x += e.translation[0] * p; dt.y += e.translation[1] * p; dt.z += e.translation[2] * p;
        } else if (e.field === 'scale') {
          ds.x += e.scale[0] * p; ds.y += e.scale[1] * p; ds.z += e.scale[2] * p;
        }
      }
      o.quaternion.fromArray(r.rotation).premultiply(dq);
      o.position.fromArray(r.translation).add(dt);
      o.scale.fromArray(r.scale).add(ds);
    }
  }

  /** The stream's value of `key` at time `t` (linear between frames, like the glTF). */
  function trackValue(key, t) {
    const v = tracks[key];
    if (!v || !stream) return 0;
    const f = Math.max(0, Math.min(t * stream.fps, v.length - 1));
    const i = Math.floor(f);
    const j = Math.min(i + 1, v.length - 1);
    return v[i] + (v[j] - v[i]) * (f - i);
  }

  function formatValue(v) {
    return Math.abs(v) >= 100 ? v.toFixed(0) : v.toFixed(1);
  }

  function showValue(name, v) {
    const s = sliders[name];
    if (!s) return;
    if (Number(s.input.value) !== v) s.input.value = String(v);
    s.output.textContent = formatValue(v) + (s.unit ? ' ' + s.unit : '');
    s.row.classList.toggle('active', v !== 0);
  }

  function buildSliders() {
    const groups = $('groups');
    let first = true;
    for (const g of model.groups) {
      const d = document.createElement('details');
      d.className = 'group';
      // Open the groups that move the mouth and the first one, so the panel starts useful.
      d.open = first || g.number === 2 || g.number === 8;
      first = false;
      const s = document.createElement('summary');
      s.innerHTML = '';
      s.append(`${g.number} · ${g.content} `);
      const c = document.createElement('span');
      c.className = 'count';
      c.textContent = `(${g.keys.length})`;
      s.append(c);
      d.append(s);
      for (const k of g.keys) {
        const row = document.createElement('div');
        row.className = 'fap';
        const id = 'fap-' + k.key;
        const label = document.createElement('label');
        label.htmlFor = id;
        label.textContent = k.label;
        label.title = k.fapu ? `${k.label} (in ${k.fapu})` : `${k.label} (0..63)`;
        const input = document.createElement('input');
        input.type = 'range';
        input.id = id;
        input.dataset.key = k.key;
        input.min = String(k.min);
        input.max = String(k.max);
        input.step = k.max - k.min > 200 ? '1' : '0.5';
        input.value = '0';
        const output = document.createElement('output');
        output.htmlFor = id;
        output.className = 'mono';
        row.append(label, input, output);
        d.append(row);
        sliders[k.key] = { input, output, row, unit: k.fapu || '' };
        values[k.key] = 0;
        showValue(k.key, 0);
        input.addEventListener('input', () => setValue(k.key, Number(input.value)));
      }
      groups.append(d);
    }
    if (model.groups.length === 0) {
      $('faps-hint').textContent = 'This face has no animation tables.';
    } else {
      $('faps-hint').textContent = stream
        ? 'Sliders follow the stream; moving one pauses playback and poses the face.'
        : 'Move a slider to pose the face.';
    }
  }

  function buildFapu() {
    const table = $('fapu');
    if (model.fapu.length === 0) {
      const note = $('fapu-note');
      note.hidden = false;
      note.textContent = model.fapu_note || 'not available';
      return;
    }
    const head = table.insertRow();
    for (const h of ['unit', 'X0', 'X0 / 1024']) {
      const c = head.insertCell();
      c.textContent = h;
      c.className = 'num';
    }
    head.cells[0].className = '';
    for (const f of model.fapu) {
      const r = table.insertRow();
      r.insertCell().textContent = f.name;
      const d = r.insertCell();
      d.className = 'num';
      d.textContent = f.distance == null ? '—' : f.distance.toPrecision(4);
      const u = r.insertCell();
      u.className = 'num';
      u.textContent = f.name === 'AU' ? '1e-5 rad' : f.unit.toPrecision(3);
    }
  }

  // ---- Playback ----------------------------------------------------------------------------

  let mixer = null;
  let action = null;
  let duration = 0;
  let playing = false;
  let mode = 'pose'; // 'animation': the glb's clip drives the face; 'pose': the sliders do
  let speed = 1;

  const playButton = $('play');
  const scrub = $('scrub');

  function currentTime() {
    return action ? action.time : 0;
  }

  function updatePlayButton() {
    const on = playing && mode === 'animation';
    playButton.textContent = on ? '❚❚' : '▶';
    playButton.setAttribute('aria-label', on ? 'Pause' : 'Play');
  }

  function setTime(t) {
    if (!action) return;
    // LoopRepeat wraps t = duration to 0; stop just short of the end instead.
    const tt = Math.max(0, Math.min(t, Math.max(duration - 1e-4, 0)));
    action.time = tt;
    mixer.update(0);
    invalidate();
  }

  function enterAnimation() {
    if (!action) return;
    mode = 'animation';
    setTime(currentTime());
  }

  function play() {
    if (!action) return;
    if (mode !== 'animation') enterAnimation();
    playing = true;
    updatePlayButton();
  }

  function pause() {
    playing = false;
    updatePlayButton();
    invalidate();
  }

  function seek(t) {
    if (!action) return;
    mode = 'animation';
    setTime(t);
    syncFromStream();
    updatePlayButton();
  }

  function setValue(name, v) {
    if (mode === 'animation') syncFromStream();
    mode = 'pose';
    playing = false;
    values[name] = v;
    showValue(name, v);
    applyPose();
    updatePlayButton();
    invalidate();
  }

  function neutral() {
    mode = 'pose';
    playing = false;
    for (const k of Object.keys(values)) {
      values[k] = 0;
      showValue(k, 0);
    }
    applyPose();
    updatePlayButton();
    invalidate();
  }

  /** Sliders (and `values`) show the stream at the current time. */
  function syncFromStream() {
    const t = currentTime();
    for (const k of Object.keys(values)) {
      const v = Math.round(trackValue(k, t) * 10) / 10;
      values[k] = v;
      showValue(k, v);
    }
  }

  function updateTransport() {
    if (!stream || !action) return;
    const t = currentTime();
    $('time').textContent = `${t.toFixed(2)} / ${duration.toFixed(2)} s`;
    const frame = Math.min(Math.round(t * stream.fps), stream.frames - 1);
    $('frame').textContent = `frame ${frame}`;
    if (document.activeElement !== scrub) scrub.value = String(t);
  }

  // ---- Feature points ----------------------------------------------------------------------

  let fpPoints = null;
  const fpWorld = model.feature_points.map((p) => new T.Vector3().fromArray(p.position));

  function dotTexture() {
    const c = document.createElement('canvas');
    c.width = c.height = 64;
    const g = c.getContext('2d');
    g.beginPath();
    g.arc(32, 32, 26, 0, Math.PI * 2);
    g.fillStyle = '#ffffff';
    g.fill();
    g.lineWidth = 8;
    g.strokeStyle = '#101010';
    g.stroke();
    return new T.CanvasTexture(c);
  }

  function buildFeaturePoints() {
    const n = model.feature_points.length;
    const pos = new Float32Array(n * 3);
    const col = new Float32Array(n * 3);
    const c = new T.Color();
    model.feature_points.forEach((p, i) => {
      pos.set(p.position, i * 3);
      c.setHex(GROUP_COLORS[Number(p.id.split('.')[0])] || 0xffffff, T.SRGBColorSpace);
      col.set([c.r, c.g, c.b], i * 3);
    });
    const geo = new T.BufferGeometry();
    geo.setAttribute('position', new T.BufferAttribute(pos, 3));
    geo.setAttribute('color', new T.BufferAttribute(col, 3));
    const mat = new T.PointsMaterial({
      size: 9,
      sizeAttenuation: false,
      vertexColors: true,
      map: dotTexture(),
      transparent: true,
      alphaTest: 0.3,
      depthTest: false,
    });
    fpPoints = new T.Points(geo, mat);
    fpPoints.renderOrder = 10;
    fpPoints.visible = false;
    fpPoints.frustumCulled = false;
    scene.add(fpPoints);
  }

  const vTmp = new T.Vector3();

  /** Moves bound feature points with the current (morphed, transformed) face. */
  function updateFeaturePoints() {
    scene.updateMatrixWorld();
    model.feature_points.forEach((p, i) => {
      const objs = p.node == null ? null : meshObjects.get(p.node);
      const o = objs && objs[0];
      if (!o || p.vertices.length === 0) return;
      const acc = fpWorld[i].set(0, 0, 0);
      for (const v of p.vertices) {
        o.getVertexPosition(v, vTmp);
        acc.add(vTmp.applyMatrix4(o.matrixWorld));
      }
      acc.divideScalar(p.vertices.length);
    });
    if (fpPoints) {
      const a = fpPoints.geometry.attributes.position;
      fpWorld.forEach((w, i) => a.setXYZ(i, w.x, w.y, w.z));
      a.needsUpdate = true;
      fpPoints.geometry.computeBoundingSphere();
    }
  }

  /** Screen positions (CSS pixels from the canvas's top-left) of feature points. */
  function projectFeaturePoints(ids) {
    updateFeaturePoints();
    camera.updateMatrixWorld();
    const w = canvas.clientWidth;
    const h = canvas.clientHeight;
    const out = [];
    model.feature_points.forEach((p, i) => {
      if (ids && !ids.includes(p.id)) return;
      const s = fpWorld[i].clone().project(camera);
      out.push({ id: p.id, x: (s.x + 1) / 2 * w, y: (1 - s.y) / 2 * h });
    });
    return out;
  }

  const raycaster = new T.Raycaster();
  const pointer = new T.Vector2();
  canvas.addEventListener('pointermove', (ev) => {
    const note = $('hover-note');
    if (!fpPoints || !fpPoints.visible) {
      note.textContent = '';
      return;
    }
    const r = canvas.getBoundingClientRect();
    pointer.set(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    raycaster.params.Points.threshold = radius * 0.02;
    const hit = raycaster.intersectObject(fpPoints)[0];
    const p = hit && model.feature_points[hit.index];
    note.textContent = p ? `${p.id} — ${p.description}` : '';
  });

  // ---- Eyes -------------------------------------------------------------------------------

  /** Gives the triangles of every eyeball (model.eyes) an eye-white, iris or pupil material:
   * the glb has one material per mesh, which would draw eyes blank. Leaves out the triangles
   * of eye layers resting on the lids (model.hidden: an occlusion shell, a tear film),
   * transparent in the head's own materials and opaque in that one. */
  function paintEyes() {
    const byNode = new Map();
    const entry = (node) => {
      if (!byNode.has(node)) byNode.set(node, { eyes: [], hidden: new Set() });
      return byNode.get(node);
    };
    for (const e of model.eyes || []) entry(e.node).eyes.push(e);
    for (const h of model.hidden || []) {
      const set = entry(h.node).hidden;
      for (const v of h.vertices) set.add(v);
    }
    const keyOf = (a, b, c) => [a, b, c].sort((x, y) => x - y).join(',');
    for (const [node, { eyes, hidden }] of byNode) {
      const o = (meshObjects.get(node) || [])[0];
      if (!o || !o.geometry || !o.geometry.index || Array.isArray(o.material)) continue;
      const sets = eyes.map((e) => ({
        ball: new Set(e.vertices),
        iris: new Set(e.iris.map((t) => keyOf(...t))),
        pupil: new Set(e.pupil.map((t) => keyOf(...t))),
      }));
      const index = o.geometry.index.array;
      const buckets = [[], [], [], []];
      let left = 0;
      for (let t = 0; t + 2 < index.length; t += 3) {
        const a = index[t];
        const b = index[t + 1];
        const c = index[t + 2];
        if (hidden.has(a) && hidden.has(b) && hidden.has(c)) {
          left += 3;
          continue;
        }
        let m = 0;
        for (const s of sets) {
          if (!(s.ball.has(a) && s.ball.has(b) && s.ball.has(c))) continue;
          const k = keyOf(a, b, c);
          m = s.pupil.has(k) ? 3 : s.iris.has(k) ? 2 : 1;
          break;
        }
        buckets[m].push(a, b, c);
      }
      if (buckets[1].length + buckets[2].length + buckets[3].length + left === 0) continue;
      const out = new index.constructor(index.length - left);
      const geo = o.geometry;
      geo.clearGroups();
      let start = 0;
      buckets.forEach((tris, m) => {
        out.set(tris, start);
        if (tris.length) geo.addGroup(start, tris.length, m);
        start += tris.length;
      });
      geo.setIndex(new T.BufferAttribute(out, 1));
      if (!eyes.length) {
        geo.clearGroups();
        continue;
      }
      const base = o.material;
      const [white, iris, pupil] = eyes[0].colours;
      const paint = (rgb, roughness) => {
        const m = base.clone();
        if (m.color) m.color.setRGB(rgb[0], rgb[1], rgb[2], T.SRGBColorSpace);
        m.map = null;
        if ('roughness' in m) m.roughness = roughness;
        if ('metalness' in m) m.metalness = 0;
        return m;
      };
      o.material = [base, paint(white, 0.35), paint(iris, 0.45), paint(pupil, 0.3)];
    }
  }

  // ---- Loading and the frame loop --------------------------------------------------------------

  function decodeBase64(text) {
    const bin = atob(text);
    const out = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out.buffer;
  }

  function showError(message) {
    const e = $('load-error');
    e.hidden = false;
    e.textContent = 'Cannot show the face: ' + message;
  }

  let lastTick = performance.now();

  function renderNow() {
    if (fpPoints && fpPoints.visible) updateFeaturePoints();
    renderer.render(scene, camera);
  }

  // Frames are drawn only when something changed (playing, camera moving, a pose or display
  // change), so a paused page leaves the CPU alone.
  let dirty = true;
  function invalidate() {
    dirty = true;
  }

  function tick(now) {
    const dt = Math.min((now - lastTick) / 1000, 0.25);
    lastTick = now;
    if (mixer && mode === 'animation' && playing) {
      mixer.update(dt * speed);
      syncFromStream();
      dirty = true;
    }
    if (controls.update()) dirty = true;
    if (dirty) {
      if (mixer && mode === 'animation') updateTransport();
      renderNow();
      dirty = false;
    }
    requestAnimationFrame(tick);
  }

  function wireControls() {
    playButton.addEventListener('click', () => (playing && mode === 'animation' ? pause() : play()));
    scrub.addEventListener('input', () => {
      seek(Number(scrub.value));
    });
    $('speed').addEventListener('change', (e) => {
      speed = Number(e.target.value) || 1;
    });
    $('toggle-wireframe').addEventListener('change', (e) => {
      scene.traverse((o) => {
        if (!o.isMesh) return;
        for (const m of Array.isArray(o.material) ? o.material : [o.material]) m.wireframe = e.target.checked;
      });
      invalidate();
    });
    $('toggle-points').addEventListener('change', (e) => {
      if (fpPoints) fpPoints.visible = e.target.checked;
      if (!e.target.checked) $('hover-note').textContent = '';
      invalidate();
    });
    $('reset-camera').addEventListener('click', () => {
      frameFace();
      invalidate();
    });
    controls.addEventListener('change', invalidate);
    $('reset-pose').addEventListener('click', neutral);
    window.addEventListener('keydown', (e) => {
      if (e.code !== 'Space' || !action) return;
      const tag = e.target && e.target.tagName;
      if (tag === 'INPUT' || tag === 'SELECT' || tag === 'BUTTON') return;
      e.preventDefault();
      playing && mode === 'animation' ? pause() : play();
    });
    new ResizeObserver(() => {
      resize();
      invalidate();
    }).observe(stage);
  }

  function onLoaded(gltf) {
    const root = gltf.scene;
    scene.add(root);
    root.traverse((o) => {
      const a = gltf.parser.associations.get(o);
      if (a && a.nodes !== undefined) {
        nodeObjects.set(a.nodes, o);
        const meshes = o.isMesh ? [o] : o.children.filter((c) => {
          const ca = gltf.parser.associations.get(c);
          return c.isMesh && !(ca && ca.nodes !== undefined);
        });
        if (meshes.length) meshObjects.set(a.nodes, meshes);
      }
    });
    paintEyes();
    buildFeaturePoints();
    const clip = gltf.animations[0];
    if (clip && stream) {
      mixer = new T.AnimationMixer(root);
      action = mixer.clipAction(clip);
      action.setLoop(T.LoopRepeat, Infinity);
      action.play();
      duration = clip.duration;
      scrub.max = String(Math.max(duration, 0.001));
      scrub.step = String(1 / stream.fps / 4);
      $('transport').hidden = false;
      mode = 'animation';
      playing = true;
      mixer.update(0);
      syncFromStream();
      updateTransport();
    } else {
      applyPose();
    }
    updatePlayButton();
    resize();
    frameFace();
    renderNow();
  }

  $('face-name').textContent = model.face;
  document.title = `${model.face} · fbakit viewer`;
  $('stream-name').textContent = stream
    ? `${stream.name} · ${stream.frames} frames at ${stream.fps} fps`
    : 'neutral face · no stream';
  buildFapu();
  buildSliders();
  wireControls();
  resize();

  const ready = new Promise((resolve, reject) => {
    const loader = new T.GLTFLoader();
    loader.parse(decodeBase64($('fbakit-glb').textContent.trim()), '', (gltf) => {
      try {
        onLoaded(gltf);
        requestAnimationFrame(tick);
        resolve({ duration, frames: stream ? stream.frames : 0 });
      } catch (err) {
        showError(String(err));
        reject(err);
      }
    }, (err) => {
      showError(String(err && err.message ? err.message : err));
      reject(err);
    });
  });

  // A small scripting interface, used by the browser test and handy from the console.
  window.fbakitViewer = {
    ready,
    model,
    play,
    pause,
    seek,
    setValue,
    neutral,
    renderNow,
    projectFeaturePoints,
    state: () => ({ mode, playing, time: currentTime(), duration, speed }),
  };
})();
