// vfcapture's ONNX Runtime worker: loads one classifier with the npm package onnxruntime-node
// and runs the batches that src/classify/classifier_ort.c sends it. Started as
//
//     node -e THIS_SCRIPT PACKAGE_DIR MODEL_PATH THREADS
//
// and talks over file descriptor 3 (a Unix socket); stdout and stderr are only for crashes.
// Every message starts with four little-endian uint32s:
//
//   request  'VFRQ', n, count, shape    then count float32: n inputs laid out as the model wants;
//            shape = S, plus 0x80000000 when the layout is NHWC ([n,S,S,3], else [n,3,S,S])
//   reply    kind, bytes, a, b          then bytes of payload
//            kind 1: JSON text (the hello after loading, or {"error": "..."})
//            kind 2: logits, a = n, b = values per input, payload a * b float32
//
// The worker answers one request at a time, in order; it exits when the socket closes.
'use strict';

const net = require('net');

const REQUEST = 0x51524656; // 'VFRQ' read as a little-endian uint32
const KIND_JSON = 1, KIND_LOGITS = 2;

const [packageDir, modelPath, threadsText] = process.argv.slice(1);
const channel = new net.Socket({fd: 3, readable: true, writable: true});

function send(kind, payload, a, b) {
    const header = Buffer.alloc(16);
    header.writeUInt32LE(kind, 0);
    header.writeUInt32LE(payload.length, 4);
    header.writeUInt32LE(a >>> 0, 8);
    header.writeUInt32LE(b >>> 0, 12);
    channel.write(header);
    channel.write(payload);
}

function sendJson(value) {
    send(KIND_JSON, Buffer.from(JSON.stringify(value), 'utf8'), 0, 0);
}

// One line, as the C side prints errors.
function oneLine(error) {
    const text = String(error && error.message ? error.message : error);
    return text.replace(/\s*\n\s*/g, '; ').trim();
}

let ort, session, input, output, batchFixed = 0;

async function load() {
    ort = require(packageDir);
    ort.env.logLevel = 'error';
    const threads = Math.max(1, parseInt(threadsText, 10) || 1);
    session = await ort.InferenceSession.create(modelPath, {
        intraOpNumThreads: threads,
        interOpNumThreads: 1,
        executionMode: 'sequential',
        graphOptimizationLevel: 'all',
        logSeverityLevel: 3,
    });
    if (session.inputNames.length !== 1)
        throw new Error(`it has ${session.inputNames.length} inputs; a classifier has one image input`);
    input = session.inputMetadata[0];
    output = session.outputMetadata[0];
    // A fixed batch dimension (1 in many exports) is honoured by running in chunks of it.
    if (input.shape && typeof input.shape[0] === 'number' && input.shape[0] > 0)
        batchFixed = input.shape[0];
    return {
        version: (ort.env.versions && ort.env.versions.node) || require(packageDir + '/package.json').version,
        input: {name: input.name, type: input.type, shape: input.shape || []},
        output: {name: output.name, type: output.type, shape: output.shape || []},
    };
}

async function run(n, shape, data) {
    if (input.type !== 'float32')
        throw new Error(`its input '${input.name}' is ${input.type}; vfcapture feeds float32 images`);
    const per = data.length / n, size = shape & 0x7fffffff;
    const dims = shape & 0x80000000 ? [n, size, size, 3] : [n, 3, size, size];
    const chunk = batchFixed || n;
    let logits = null, classes = 0;
    for (let first = 0; first < n; first += chunk) {
        const m = Math.min(chunk, n - first);
        if (m !== chunk && batchFixed)
            throw new Error(`its batch size is fixed at ${batchFixed}`);
        dims[0] = m;
        const view = data.subarray(first * per, (first + m) * per);
        const result = await session.run({[input.name]: new ort.Tensor('float32', view, dims)});
        const out = result[output.name];
        if (out.type !== 'float32')
            throw new Error(`its output '${output.name}' is ${out.type}, not float32 scores`);
        classes = out.data.length / m;
        if (!logits)
            logits = new Float32Array(n * classes);
        logits.set(out.data, first * classes);
    }
    return {logits, classes};
}

// Requests arrive in pieces; copy each one's floats straight into its own array.
let header = Buffer.alloc(0), pending = null, filled = 0, busy = Promise.resolve();

function onData(chunk) {
    while (chunk.length > 0) {
        if (!pending) {
            const need = 16 - header.length;
            header = Buffer.concat([header, chunk.subarray(0, need)]);
            chunk = chunk.subarray(need);
            if (header.length < 16)
                return;
            if (header.readUInt32LE(0) !== REQUEST) {
                process.stderr.write('vf-ort: bad request header\n');
                process.exit(3);
            }
            pending = {n: header.readUInt32LE(4), data: new Float32Array(header.readUInt32LE(8)),
                       shape: header.readUInt32LE(12)};
            filled = 0;
            header = Buffer.alloc(0);
        }
        const bytes = Buffer.from(pending.data.buffer);
        const take = Math.min(chunk.length, bytes.length - filled);
        chunk.copy(bytes, filled, 0, take);
        filled += take;
        chunk = chunk.subarray(take);
        if (filled === bytes.length) {
            const request = pending;
            pending = null;
            busy = busy.then(() => run(request.n, request.shape, request.data))
                .then(({logits, classes}) =>
                    send(KIND_LOGITS, Buffer.from(logits.buffer), request.n, classes))
                .catch((error) => sendJson({error: oneLine(error)}));
        }
    }
}

load().then((hello) => {
    sendJson(hello);
    channel.on('data', onData);
}, (error) => {
    sendJson({error: oneLine(error)});
    channel.end(() => process.exit(0));
});
channel.on('end', () => busy.then(() => process.exit(0)));
channel.on('error', () => process.exit(0));
