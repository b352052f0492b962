// The report's 3D view of a wall's run, written for framewright's report (plain WebGL, no
// library). Every `figure.viewer` on the page holds its wall's scene (the GLB that
// `report::glb` writes, deflated and base64-encoded) in a `script.viewer-scene`; this script
// parses it, draws the nodes' meshes in their materials' base colours, plays the animation,
// turns the camera about the scene (drag, wheel) and tells which piece a click hits (the
// scene drawn once more into an offscreen buffer, each piece in a colour of its own).
// Text from the model is only ever set with textContent or copied from the page's own nodes.
(function () {
  'use strict';

  // ---- 4x4 matrices, column-major as WebGL takes them ----
  function multiply(a, b) {
    const o = new Array(16);
    for (let c = 0; c < 4; c++) {
      for (let r = 0; r < 4; r++) {
        let s = 0;
        for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
        o[c * 4 + r] = s;
      }
    }
    return o;
  }

  // Translation, rotation (quaternion x, y, z, w) and scale in one matrix.
  function compose(t, q, s) {
    const [x, y, z, w] = q;
    return [
      (1 - 2 * (y * y + z * z)) * s[0], 2 * (x * y + w * z) * s[0], 2 * (x * z - w * y) * s[0], 0,
      2 * (x * y - w * z) * s[1], (1 - 2 * (x * x + z * z)) * s[1], 2 * (y * z + w * x) * s[1], 0,
      2 * (x * z + w * y) * s[2], 2 * (y * z - w * x) * s[2], (1 - 2 * (x * x + y * y)) * s[2], 0,
      t[0], t[1], t[2], 1,
    ];
  }

  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
      0, 0, (2 * far * near) / (near - far), 0];
  }

  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function normalize(a) { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }

  function lookAt(eye, target, up) {
    const z = normalize(sub(eye, target));
    const x = normalize(cross(up, z));
    const y = cross(z, x);
    return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
  }

  function apply(m, p) {
    const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
    return [0, 1, 2].map((i) => (m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i]) / w);
  }

  // ---- the GLB: 12-byte header, a JSON chunk, a BIN chunk ----
  function parseGlb(bytes) {
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    if (view.getUint32(0, true) !== 0x46546c67 || view.getUint32(4, true) !== 2) {
      throw new Error('not a glTF 2.0 binary');
    }
    let json = null;
    let bin = new Uint8Array(0);
    for (let at = 12; at + 8 <= bytes.length;) {
      const length = view.getUint32(at, true);
      const type = view.getUint32(at + 4, true);
      const body = bytes.subarray(at + 8, at + 8 + length);
      if (type === 0x4e4f534a) json = JSON.parse(new TextDecoder().decode(body));
      if (type === 0x004e4942) bin = body;
      at += 8 + length;
    }
    if (!json) throw new Error('no JSON chunk');
    return { json, bin };
  }

  const WIDTHS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 };
  const TYPES = { 5121: Uint8Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };

  // An accessor's values as a typed array (copied, so aligned; strided views gathered).
  function read(gltf, index) {
    const { json, bin } = gltf;
    const a = json.accessors[index];
    const Type = TYPES[a.componentType];
    const width = WIDTHS[a.type];
    const out = new Type(a.count * width);
    if (a.bufferView === undefined) return out;
    const v = json.bufferViews[a.bufferView];
    const start = (v.byteOffset || 0) + (a.byteOffset || 0);
    const size = width * Type.BYTES_PER_ELEMENT;
    const stride = v.byteStride || size;
    if (stride === size) return new Type(bin.slice(start, start + a.count * size).buffer);
    for (let i = 0; i < a.count; i++) {
      const from = bin.slice(start + i * stride, start + i * stride + size);
      out.set(new Type(from.buffer), i * width);
    }
    return out;
  }

  // ---- animation: a channel's value at time t ----
  function sample(ch, t) {
    const times = ch.times;
    const n = ch.width;
    const last = times.length - 1;
    const value = (k) => Array.from(ch.values.subarray(k * n, k * n + n));
    if (t <= times[0]) return value(0);
    if (t >= times[last]) return value(last);
    let lo = 0;
    let hi = last;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid;
    }
    if (ch.step) return value(lo);
    const s = (t - times[lo]) / (times[hi] - times[lo]);
    const a = value(lo);
    const b = value(hi);
    return ch.path === 'rotation' ? slerp(a, b, s) : a.map((x, i) => x + (b[i] - x) * s);
  }

  function slerp(a, b, s) {
    let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0) { b = b.map((x) => -x); d = -d; }
    if (d > 0.9995) return normalize4(a.map((x, i) => x + (b[i] - x) * s));
    const angle = Math.acos(d);
    const wa = Math.sin((1 - s) * angle) / Math.sin(angle);
    const wb = Math.sin(s * angle) / Math.sin(angle);
    return a.map((x, i) => wa * x + wb * b[i]);
  }

  function normalize4(q) { const l = Math.hypot(q[0], q[1], q[2], q[3]) || 1; return q.map((x) => x / l); }

  // ---- the scene ----
  function buildScene(gl, gltf) {
    const json = gltf.json;
    const nodes = (json.nodes || []).map((n) => ({
      name: n.name || '',
      mesh: n.mesh,
      children: n.children || [],
      matrix: n.matrix,
      t: n.translation || [0, 0, 0],
      r: n.rotation || [0, 0, 0, 1],
      s: n.scale || [1, 1, 1],
    }));
    const meshes = (json.meshes || []).map((m) => m.primitives.filter((p) => (p.mode === undefined || p.mode === 4) && p.attributes.POSITION !== undefined).map((p) => primitive(gl, gltf, p)));
    const channels = [];
    for (const anim of (json.animations || []).slice(0, 1)) {
      for (const c of anim.channels) {
        const smp = anim.samplers[c.sampler];
        if (c.target.node === undefined || !['translation', 'rotation', 'scale'].includes(c.target.path)) continue;
        const times = read(gltf, smp.input);
        const values = read(gltf, smp.output);
        channels.push({ node: c.target.node, path: c.target.path, times, values,
          width: c.target.path === 'rotation' ? 4 : 3, step: smp.interpolation === 'STEP' });
      }
    }
    const duration = channels.reduce((d, c) => Math.max(d, c.times[c.times.length - 1] || 0), 0);
    nodes.forEach((n) => { n.piece = n.name.startsWith('piece ') ? n.name.slice(6) : null; });
    const scene = json.scenes ? json.scenes[json.scene || 0] : { nodes: nodes.map((_, i) => i) };
    // The work the camera frames first: the robot, its tool and the lumber.
    const focus = (i, inside) => {
      const n = nodes[i];
      n.focus = inside || /^(link |piece |tool)/.test(n.name);
      n.children.forEach((c) => focus(c, n.focus));
    };
    (scene.nodes || []).forEach((i) => focus(i, false));
    return { nodes, meshes, channels, duration, roots: scene.nodes || [] };
  }

  function primitive(gl, gltf, p) {
    const material = p.material !== undefined ? gltf.json.materials[p.material] : {};
    const pbr = material.pbrMetallicRoughness || {};
    let positions = read(gltf, p.attributes.POSITION);
    let normals = p.attributes.NORMAL !== undefined ? read(gltf, p.attributes.NORMAL) : null;
    let indices = p.indices !== undefined ? read(gltf, p.indices) : null;
    if (!normals) {
      // Flat normals: every triangle its own three vertices.
      const corners = indices || Array.from({ length: positions.length / 3 }, (_, i) => i);
      const flat = new Float32Array(corners.length * 3);
      const nor = new Float32Array(corners.length * 3);
      for (let k = 0; k + 2 < corners.length; k += 3) {
        const v = [0, 1, 2].map((j) => Array.from(positions.subarray(corners[k + j] * 3, corners[k + j] * 3 + 3)));
        const n = normalize(cross(sub(v[1], v[0]), sub(v[2], v[0])));
        for (let j = 0; j < 3; j++) { flat.set(v[j], (k + j) * 3); nor.set(n, (k + j) * 3); }
      }
      positions = flat;
      normals = nor;
      indices = null;
    }
    const buffer = (target, data) => {
      const b = gl.createBuffer();
      gl.bindBuffer(target, b);
      gl.bufferData(target, data, gl.STATIC_DRAW);
      return b;
    };
    const a = gltf.json.accessors[p.attributes.POSITION];
    const out = {
      position: buffer(gl.ARRAY_BUFFER, positions),
      normal: buffer(gl.ARRAY_BUFFER, normals),
      count: indices ? indices.length : positions.length / 3,
      colour: pbr.baseColorFactor || [1, 1, 1, 1],
      min: a.min, max: a.max,
    };
    if (indices) {
      const type = indices instanceof Uint32Array ? gl.UNSIGNED_INT : indices instanceof Uint16Array ? gl.UNSIGNED_SHORT : gl.UNSIGNED_BYTE;
      out.index = buffer(gl.ELEMENT_ARRAY_BUFFER, indices);
      out.indexType = type;
    }
    return out;
  }

  // Every node's world matrix at time t (animated values replace the node's own), and which
  // pieces are not in the world then: those are drawn faint where they rest, at their target.
  function pose(scene, t) {
    const local = scene.nodes.map((n) => ({ t: n.t, r: n.r, s: n.s }));
    const key = { translation: 't', rotation: 'r', scale: 's' };
    for (const c of scene.channels) local[c.node][key[c.path]] = sample(c, t);
    const ghost = new Set();
    scene.nodes.forEach((n, i) => {
      if (n.piece !== null && local[i].s.every((x) => x === 0)) {
        ghost.add(i);
        local[i] = { t: n.t, r: n.r, s: [1, 1, 1] };
      }
    });
    const world = new Array(scene.nodes.length);
    const walk = (i, parent) => {
      const n = scene.nodes[i];
      const m = n.matrix || compose(local[i].t, local[i].r, local[i].s);
      world[i] = parent ? multiply(parent, m) : m;
      n.children.forEach((c) => walk(c, world[i]));
    };
    scene.roots.forEach((i) => walk(i, null));
    world.ghost = ghost;
    return world;
  }

  // ---- drawing ----
  const VERTEX = `
    attribute vec3 position; attribute vec3 normal;
    uniform mat4 model; uniform mat4 viewProjection;
    varying vec3 vNormal;
    void main() {
      vNormal = (model * vec4(normal, 0.0)).xyz;
      gl_Position = viewProjection * model * vec4(position, 1.0);
    }`;
  const SHADED = `
    precision mediump float;
    uniform vec4 colour; uniform vec3 light; uniform float highlight;
    varying vec3 vNormal;
    void main() {
      vec3 n = normalize(vNormal);
      if (!gl_FrontFacing) n = -n;
      float sky = 0.5 + 0.5 * n.y;
      vec3 c = colour.rgb * (0.30 + 0.25 * sky + 0.6 * max(dot(n, light), 0.0));
      c = mix(c, vec3(1.0, 0.92, 0.2), highlight);
      gl_FragColor = vec4(pow(c, vec3(1.0 / 2.2)), colour.a);
    }`;
  const FLAT = `
    precision mediump float;
    uniform vec4 colour;
    void main() { gl_FragColor = colour; }`;
  const BACKGROUND = [0.96, 0.97, 0.98];

  function program(gl, fragment) {
    const p = gl.createProgram();
    for (const [type, text] of [[gl.VERTEX_SHADER, VERTEX], [gl.FRAGMENT_SHADER, fragment]]) {
      const s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      gl.attachShader(p, s);
    }
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('shaders: ' + gl.getProgramInfoLog(p));
    const at = (name) => gl.getUniformLocation(p, name);
    return { p, position: gl.getAttribLocation(p, 'position'), normal: gl.getAttribLocation(p, 'normal'),
      model: at('model'), viewProjection: at('viewProjection'), colour: at('colour'), light: at('light'), highlight: at('highlight') };
  }

  function Viewer(figure) {
    const canvas = figure.querySelector('canvas');
    const gl = canvas.getContext('webgl2') || canvas.getContext('webgl');
    if (!gl) throw new Error('no WebGL');
    if (!(typeof WebGL2RenderingContext !== 'undefined' && gl instanceof WebGL2RenderingContext)) {
      gl.getExtension('OES_element_index_uint');
    }
    this.figure = figure;
    this.canvas = canvas;
    this.gl = gl;
    this.shaded = program(gl, SHADED);
    this.flat = program(gl, FLAT);
    this.section = figure.closest('section') || document;
    this.time = 0;
    this.playing = false;
    this.selected = null;
  }

  Viewer.prototype.load = function (gltf) {
    const scene = buildScene(this.gl, gltf);
    this.scene = scene;
    this.pieces = scene.nodes.filter((n) => n.piece !== null && n.mesh !== undefined);
    this.time = scene.duration;
    // The camera fits the robot and the lumber at the run's end (else the scene but its floor,
    // else all of it).
    const world = pose(scene, scene.duration);
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    const grow = (within) => scene.nodes.forEach((n, i) => {
      if (n.mesh === undefined || !within(n) || !visible(world[i])) return;
      for (const prim of scene.meshes[n.mesh]) {
        if (!prim.min || !prim.max) continue;
        for (let c = 0; c < 8; c++) {
          const p = apply(world[i], [0, 1, 2].map((k) => ((c >> k) & 1 ? prim.max[k] : prim.min[k])));
          for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
        }
      }
    });
    grow((n) => n.focus);
    if (!(lo[0] < hi[0])) grow((n) => n.name !== 'floor');
    if (!(lo[0] < hi[0])) grow(() => true);
    if (!(lo[0] <= hi[0])) { lo.fill(-1); hi.fill(1); }
    this.target = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    this.radius = Math.max(0.5, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
    this.distance = this.radius / Math.sin(Math.PI / 8) * 0.95;
    this.yaw = 0.6;
    this.pitch = 0.5;
  };

  function visible(m) {
    return Math.abs(m[0] * (m[5] * m[10] - m[6] * m[9]) - m[4] * (m[1] * m[10] - m[2] * m[9]) + m[8] * (m[1] * m[6] - m[2] * m[5])) > 1e-12;
  }

  Viewer.prototype.camera = function () {
    const c = this.canvas;
    const eye = [
      this.target[0] + this.distance * Math.cos(this.pitch) * Math.sin(this.yaw),
      this.target[1] + this.distance * Math.sin(this.pitch),
      this.target[2] + this.distance * Math.cos(this.pitch) * Math.cos(this.yaw),
    ];
    const near = Math.max(0.01, this.distance - this.radius * 4);
    const view = lookAt(eye, this.target, [0, 1, 0]);
    return { eye, matrix: multiply(perspective(Math.PI / 4, c.width / c.height, near, this.distance + this.radius * 4), view) };
  };

  // Draws the scene: `pick` draws each piece in the colour of its number (1, 2, ...) and the
  // rest in black, into the offscreen buffer.
  Viewer.prototype.draw = function (pick) {
    const gl = this.gl;
    const scene = this.scene;
    const world = pose(scene, this.time);
    const cam = this.camera();
    const prog = pick ? this.flat : this.shaded;
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
    gl.clearColor(...(pick ? [0, 0, 0] : BACKGROUND), 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(prog.p);
    gl.uniformMatrix4fv(prog.viewProjection, false, cam.matrix);
    if (!pick) {
      // Light from over the viewer's right shoulder.
      const toEye = normalize(sub(cam.eye, this.target));
      gl.uniform3fv(prog.light, normalize([toEye[0] + 0.3 * Math.cos(this.yaw), toEye[1] + 0.8, toEye[2] - 0.3 * Math.sin(this.yaw)]));
    }
    const order = [];
    scene.nodes.forEach((n, i) => { if (n.mesh !== undefined && visible(world[i])) order.push(i); });
    // Opaque first, then the faint pieces blended over them.
    const ghost = world.ghost;
    order.sort((a, b) => ghost.has(a) - ghost.has(b));
    for (const i of order) {
      const n = scene.nodes[i];
      const faint = ghost.has(i);
      const chosen = n.piece !== null && n.piece === this.selected;
      if (pick) {
        const k = n.piece === null ? 0 : this.pieces.indexOf(n) + 1;
        gl.uniform4fv(prog.colour, [(k & 255) / 255, ((k >> 8) & 255) / 255, ((k >> 16) & 255) / 255, 1]);
      } else {
        gl.uniform1f(prog.highlight, chosen ? 0.45 : 0);
        if (faint && !chosen) {
          gl.enable(gl.BLEND);
          gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
          gl.depthMask(false);
        } else {
          gl.disable(gl.BLEND);
          gl.depthMask(true);
        }
      }
      gl.uniformMatrix4fv(prog.model, false, world[i]);
      for (const prim of scene.meshes[n.mesh]) {
        if (!pick) gl.uniform4fv(prog.colour, [prim.colour[0], prim.colour[1], prim.colour[2], faint && !chosen ? 0.3 : 1]);
        gl.bindBuffer(gl.ARRAY_BUFFER, prim.position);
        gl.enableVertexAttribArray(prog.position);
        gl.vertexAttribPointer(prog.position, 3, gl.FLOAT, false, 0, 0);
        if (prog.normal >= 0) {
          gl.bindBuffer(gl.ARRAY_BUFFER, prim.normal);
          gl.enableVertexAttribArray(prog.normal);
          gl.vertexAttribPointer(prog.normal, 3, gl.FLOAT, false, 0, 0);
        }
        if (prim.index) {
          gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, prim.index);
          gl.drawElements(gl.TRIANGLES, prim.count, prim.indexType, 0);
        } else {
          gl.drawArrays(gl.TRIANGLES, 0, prim.count);
        }
      }
    }
    gl.disable(gl.BLEND);
    gl.depthMask(true);
  };

  // The piece (its id) drawn at canvas pixel (x, y) from the top left, or null.
  Viewer.prototype.pieceAt = function (x, y) {
    const gl = this.gl;
    const w = this.canvas.width;
    const h = this.canvas.height;
    if (!this.pick || this.pick.w !== w || this.pick.h !== h) {
      const fb = gl.createFramebuffer();
      const colour = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, colour);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      const depth = gl.createRenderbuffer();
      gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
      gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT16, w, h);
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, colour, 0);
      gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
      this.pick = { fb, w, h };
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.pick.fb);
    this.draw(true);
    const px = new Uint8Array(4);
    gl.readPixels(Math.round(x), Math.round(h - 1 - y), 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    const k = px[0] + 256 * px[1] + 65536 * px[2];
    return k > 0 && k <= this.pieces.length ? this.pieces[k - 1].piece : null;
  };

  // Where a piece's centre is drawn now (canvas pixels from the top left), or null.
  Viewer.prototype.project = function (id) {
    const i = this.scene.nodes.findIndex((n) => n.piece === id);
    if (i < 0) return null;
    const n = this.scene.nodes[i];
    const prim = this.scene.meshes[n.mesh][0];
    const world = pose(this.scene, this.time);
    if (!visible(world[i])) return null;
    const centre = apply(world[i], [0, 1, 2].map((k) => (prim.min[k] + prim.max[k]) / 2));
    const p = apply(this.camera().matrix, centre);
    return [(p[0] + 1) / 2 * this.canvas.width, (1 - p[1]) / 2 * this.canvas.height];
  };

  // ---- the page around the canvas ----
  function byId(root, selector, id) {
    return Array.from(root.querySelectorAll(selector)).filter((e) => e.getAttribute('data-id') === id);
  }

  Viewer.prototype.select = function (id) {
    this.selected = id;
    for (const e of this.section.querySelectorAll('.picked')) e.classList.remove('picked');
    const info = this.figure.querySelector('.viewer-info');
    info.textContent = '';
    if (id === null) {
      const p = document.createElement('p');
      p.textContent = 'Click a piece for its verdict and why.';
      info.append(p);
    } else {
      const shape = byId(this.section, 'svg.elevation g.piece', id)[0];
      const verdict = shape ? shape.getAttribute('data-verdict') : 'not in the drawing';
      const head = document.createElement('p');
      const strong = document.createElement('strong');
      strong.textContent = id;
      head.append(strong, ' \u2014 ' + verdict.replace(/-/g, ' '));
      info.append(head);
      const causes = byId(this.section, '.causes li', id);
      for (const li of causes) {
        li.classList.add('picked');
        const copy = document.createElement('div');
        copy.className = 'why';
        copy.append(...Array.from(li.cloneNode(true).childNodes));
        info.append(copy);
      }
      const title = shape && shape.querySelector('title');
      if (!causes.length && title && verdict !== 'framed') {
        const p = document.createElement('p');
        p.textContent = title.textContent;
        info.append(p);
      }
      if (shape) shape.classList.add('picked');
      for (const row of byId(this.section, 'svg.timeline g.row', id)) row.classList.add('picked');
    }
    this.render();
  };

  Viewer.prototype.render = function () {
    this.draw(false);
    const max = this.scene.duration;
    this.slider.value = String(this.time);
    this.clock.textContent = this.time.toFixed(1) + ' s of ' + max.toFixed(1) + ' s';
    if (this.cursor) {
      const x = this.left + this.time * this.scale;
      this.cursor.setAttribute('x1', x.toFixed(1));
      this.cursor.setAttribute('x2', x.toFixed(1));
    }
  };

  // Counts the pixels drawn in something other than the background.
  Viewer.prototype.drawn = function () {
    const gl = this.gl;
    const w = this.canvas.width;
    const h = this.canvas.height;
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const bg = BACKGROUND.map((c) => Math.round(c * 255));
    let n = 0;
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]) > 6) n++;
    }
    return n;
  };

  Viewer.prototype.bind = function () {
    const f = this.figure;
    const canvas = this.canvas;
    this.slider = f.querySelector('input.time');
    this.clock = f.querySelector('output.clock');
    const play = f.querySelector('button.play');
    const speed = f.querySelector('select.speed');
    this.slider.max = String(this.scene.duration);
    this.slider.addEventListener('input', () => { this.time = Number(this.slider.value); this.render(); });
    let last = null;
    const tick = (now) => {
      if (!this.playing) return;
      if (last !== null) this.time = Math.min(this.scene.duration, this.time + (now - last) / 1000 * Number(speed.value));
      last = now;
      this.render();
      if (this.time >= this.scene.duration) { this.playing = false; play.textContent = 'Play'; return; }
      requestAnimationFrame(tick);
    };
    play.addEventListener('click', () => {
      this.playing = !this.playing;
      play.textContent = this.playing ? 'Pause' : 'Play';
      if (this.playing) {
        if (this.time >= this.scene.duration) this.time = 0;
        last = null;
        requestAnimationFrame(tick);
      }
    });
    // The timeline below follows the view, and a click on it moves the view to that time.
    const timeline = this.section.querySelector('svg.timeline');
    if (timeline && timeline.hasAttribute('data-left')) {
      this.left = Number(timeline.getAttribute('data-left'));
      this.scale = Number(timeline.getAttribute('data-px-per-s'));
      this.cursor = document.createElementNS('http://www.w3.org/2000/svg', 'line');
      this.cursor.setAttribute('class', 'now');
      this.cursor.setAttribute('y1', '0');
      this.cursor.setAttribute('y2', String(timeline.viewBox.baseVal.height - 30));
      timeline.append(this.cursor);
      timeline.addEventListener('click', (e) => {
        const box = timeline.getBoundingClientRect();
        const x = (e.clientX - box.left) * timeline.viewBox.baseVal.width / box.width;
        const t = (x - this.left) / this.scale;
        if (t >= 0 && t <= this.scene.duration) { this.time = t; this.render(); }
      });
    }
    // Drag turns the view, the wheel zooms, a click (no drag) picks.
    let down = null;
    canvas.addEventListener('pointerdown', (e) => {
      down = { x: e.clientX, y: e.clientY, yaw: this.yaw, pitch: this.pitch, moved: false };
      // A pointer the browser does not know (an event made by a script) cannot be captured.
      try { canvas.setPointerCapture(e.pointerId); } catch (_) { /* the drag ends at the edge */ }
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!down || !(e.buttons & 1)) return;
      const dx = e.clientX - down.x;
      const dy = e.clientY - down.y;
      if (Math.abs(dx) + Math.abs(dy) > 3) down.moved = true;
      this.yaw = 0.6;
      this.pitch = Math.max(-0.2, Math.min(1.5, down.pitch + dy * 0.01));
      this.render();
    });
    canvas.addEventListener('pointerup', (e) => {
      if (down && !down.moved) {
        const box = canvas.getBoundingClientRect();
        const x = (e.clientX - box.left) * canvas.width / box.width;
        const y = (e.clientY - box.top) * canvas.height / box.height;
        this.select(this.pieceAt(x, y));
      }
      down = null;
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.distance = Math.max(this.radius * 0.2, Math.min(this.radius * 8, this.distance * Math.exp(e.deltaY * 0.001)));
      this.render();
    }, { passive: false });
  };

  // The scene from its script element: base64 of the GLB deflated (zlib).
  async function sceneBytes(figure) {
    const text = figure.querySelector('script.viewer-scene').textContent.trim();
    const raw = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
    const stream = new Blob([raw]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  async function start(figure) {
    const message = figure.querySelector('.viewer-message');
    try {
      if (typeof DecompressionStream === 'undefined') throw new Error('no DecompressionStream');
      const viewer = new Viewer(figure);
      viewer.load(parseGlb(await sceneBytes(figure)));
      for (const e of figure.querySelectorAll('[hidden]')) e.hidden = false;
      message.hidden = true;
      const canvas = viewer.canvas;
      canvas.width = Math.round(canvas.clientWidth * (window.devicePixelRatio || 1)) || canvas.width;
      canvas.height = Math.round(canvas.width * 9 / 16);
      viewer.bind();
      viewer.select(null);
      figure.viewer = viewer;
      figure.setAttribute('data-pieces', String(viewer.pieces.length));
      figure.setAttribute('data-meshes', String(viewer.scene.nodes.filter((n) => n.mesh !== undefined).length));
      figure.setAttribute('data-duration', viewer.scene.duration.toFixed(3));
      figure.setAttribute('data-drawn', String(viewer.drawn()));
    } catch (e) {
      message.prepend('The 3D view could not be shown here (' + e.message + '). ');
      figure.setAttribute('data-error', e.message);
    }
  }

  for (const figure of document.querySelectorAll('figure.viewer')) start(figure);
})();
