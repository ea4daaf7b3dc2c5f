// specfx_folded: the `folded` microarchitecture of docs/cycle.md (Rust: src/cycle/).
// One shared multiplier does the K + 2 multiplications of an input in turn, driven by an FSM;
// sub and add_b are combinational around it. Each multiplication takes LAT_MUL cycles: the
// multiplier is combinational and its operands are held for LAT_MUL cycles (a multicycle
// path), the result being taken on the last one. LAT_SUB and LAT_ADD do not apply.
//
//   step 0:      x <= b = Q_b(cutoff(Q_t(x * slope) + offset))   (x holds d on entry)
//   step i:      x <= sq_i = Q_i(x * x), i = 1..K
//   step K + 1:  out_data <= Q_out(x * coef)
//
// Handshake (docs/cycle.md): out_free = !out_valid || out_ready;
// last = busy && step == K + 1 && count == LAT_MUL - 1; in_ready = (!busy || last) && out_free.
// An input can enter in the same cycle as the previous result moves to the output register.
// Latency (K + 2) * LAT_MUL + 1 cycles to the output register; initiation interval
// (K + 2) * LAT_MUL cycles.
//
// Parameters as specfx_pipelined (formats, packed squaring-stage vectors, mode codes,
// RESET_DATA, DEPTH_MIN). Per-n depth: step i > in_depth (held in depth_r) requantizes x
// instead of x * x (specfx_sq_quant's bypass, on steps i > DEPTH_MIN only); the multiplier
// still runs and the step takes its LAT_MUL cycles, so latency and initiation interval are the
// same for every n.
`timescale 1ns / 1ps
`default_nettype none

module specfx_folded #(
    parameter integer K        = 4,
    parameter integer CUTOFF   = 0,
    parameter integer C_W      = 16,
    parameter integer C_F      = 15,
    parameter integer C_S      = 0,
    parameter integer D_W      = 16,
    parameter integer D_F      = 15,
    parameter integer SLOPE_W  = 11,
    parameter integer SLOPE_F  = 4,
    parameter integer SLOPE_S  = 0,
    parameter integer OFFSET_W = 1,
    parameter integer OFFSET_F = 0,
    parameter integer OFFSET_S = 0,
    parameter integer T_W      = 18,
    parameter integer T_F      = 16,
    parameter integer T_S      = 1,
    parameter integer T_RND    = 2,
    parameter integer T_OVF    = 1,
    parameter integer B_W      = 17,
    parameter integer B_F      = 16,
    parameter integer B_S      = 0,
    parameter integer B_RND    = 2,
    parameter integer B_OVF    = 1,
    parameter [111:0] SQ_W     = {7{16'd17}},
    parameter [111:0] SQ_F     = {7{16'd16}},
    parameter [111:0] SQ_S     = {7{16'd0}},
    parameter [111:0] SQ_RND   = {7{16'd2}},
    parameter [111:0] SQ_OVF   = {7{16'd1}},
    parameter integer COEF_W   = 24,
    parameter integer COEF_F   = 16,
    parameter integer COEF_S   = 0,
    parameter integer OUT_W    = 24,
    parameter integer OUT_F    = 16,
    parameter integer OUT_S    = 0,
    parameter integer OUT_RND  = 2,
    parameter integer OUT_OVF  = 1,
    parameter integer LAT_MUL  = 1,
    parameter integer RESET_DATA = 0,
    parameter integer DEPTH_MIN = 7
) (
    input  wire                clk,
    input  wire                rst,
    input  wire                in_valid,
    output wire                in_ready,
    input  wire [C_W-1:0]      in_c,
    input  wire [SLOPE_W-1:0]  in_slope,
    input  wire [OFFSET_W-1:0] in_offset,
    input  wire [C_W-1:0]      in_threshold,
    input  wire [COEF_W-1:0]   in_coef,
    input  wire [2:0]          in_depth,
    output reg                 out_valid,
    input  wire                out_ready,
    output reg  [OUT_W-1:0]    out_data
);
    // ---- Formats of the squaring chain: stage 0 is b, stage i (1..K) is sq_i. ----
    function integer sq_field(input [111:0] packed_fields, input integer i, input integer is_signed);
        reg [15:0] f;
        begin
            f = packed_fields[16*i-1 -: 16];
            sq_field = {{16{(is_signed != 0) & f[15]}}, f};
        end
    endfunction
    function integer chain_w(input integer i);
        chain_w = (i == 0) ? B_W : sq_field(SQ_W, i, 0);
    endfunction
    function integer chain_f(input integer i);
        chain_f = (i == 0) ? B_F : sq_field(SQ_F, i, 1);
    endfunction
    function integer chain_s(input integer i);
        chain_s = (i == 0) ? B_S : sq_field(SQ_S, i, 0);
    endfunction
    // Width of a signed register holding d and every chain value up to sq_last.
    function integer operand_w(input integer last);
        integer i;
        begin
            operand_w = D_W;
            for (i = 0; i <= last; i = i + 1)
                if (chain_w(i) + 1 > operand_w) operand_w = chain_w(i) + 1;
        end
    endfunction

    // Width of the widest exact square sq_{i-1}^2, i = 1..last.
    function integer square_w(input integer last);
        integer i;
        begin
            square_w = 0;
            for (i = 1; i <= last; i = i + 1)
                if (2 * chain_w(i - 1) + ((chain_s(i - 1) != 0) ? 0 : 1) > square_w)
                    square_w = 2 * chain_w(i - 1) + ((chain_s(i - 1) != 0) ? 0 : 1);
        end
    endfunction

    localparam integer X_W = operand_w(K);                       // x, signed
    localparam integer SLOPE_XW = SLOPE_W + 1;
    localparam integer COEF_XW = COEF_W + 1;
    localparam integer Y_W0 = (SLOPE_XW > COEF_XW) ? SLOPE_XW : COEF_XW;
    localparam integer Y_W = (X_W > Y_W0) ? X_W : Y_W0;          // second operand, signed
    // The product bits any step uses: each step's exact product fits in its own low bits.
    localparam integer PT_W = D_W + SLOPE_W;                               // d * slope
    localparam integer PO_W = chain_w(K) + COEF_W
                            + ((chain_s(K) != 0 || COEF_S != 0) ? 0 : 1);  // sq_K * coef
    localparam integer P_W0 = (PT_W > PO_W) ? PT_W : PO_W;
    localparam integer P_W = (square_w(K) > P_W0) ? square_w(K) : P_W0;
    localparam integer STEP_W = $clog2(K + 2);
    localparam integer CNT_W = (LAT_MUL > 1) ? $clog2(LAT_MUL) : 1;
    localparam integer STEP_LAST_I = K + 1;
    localparam integer CNT_LAST_I = LAT_MUL - 1;
    localparam [STEP_W-1:0] STEP_LAST = STEP_LAST_I[STEP_W-1:0];
    localparam [CNT_W-1:0] CNT_LAST = CNT_LAST_I[CNT_W-1:0];

    // ---- Registers. ----
    reg                busy;
    reg [STEP_W-1:0]   step;
    reg [CNT_W-1:0]    count;
    reg [X_W-1:0]      x;
    reg [SLOPE_W-1:0]  slope_r;
    reg [OFFSET_W-1:0] offset_r;
    reg [C_W-1:0]      threshold_r;
    reg [C_W-1:0]      c_cl_r;
    reg [COEF_W-1:0]   coef_r;
    reg [2:0]          depth_r;

    // ---- Handshake. ----
    wire out_free = !out_valid || out_ready;
    wire count_done = (count == CNT_LAST);
    wire last = busy && (step == STEP_LAST) && count_done;
    assign in_ready = (!busy || last) && out_free;
    wire in_fire = in_valid && in_ready;
    wire step_done = busy && !last && count_done;  // x takes the step's result
    wire out_load = last && out_free;              // the output register takes the result

    // Which step is running (one-hot decode of `step`).
    wire [K+1:0] at_step;
    genvar s;
    generate
        for (s = 0; s <= K + 1; s = s + 1) begin : g_decode
            localparam integer S_I = s;
            localparam [STEP_W-1:0] S_CODE = S_I[STEP_W-1:0];
            assign at_step[s] = (step == S_CODE);
        end
    endgenerate

    // ---- The new input: clamp and subtract are combinational. ----
    wire [C_W-1:0] c_cl_in;
    wire [D_W-1:0] d_in;
    specfx_sub #(.C_W(C_W), .C_F(C_F), .C_S(C_S), .D_W(D_W), .D_F(D_F)) u_sub (
        .c(in_c), .c_clamped(c_cl_in), .d(d_in)
    );
    wire [X_W-1:0] d_x;
    specfx_extend #(.IN_W(D_W), .IN_S(1), .OUT_W(X_W)) u_d_x (.x(d_in), .y(d_x));

    // ---- The shared multiplier: x * slope (step 0), x * x (1..K), x * coef (K + 1). ----
    wire [Y_W-1:0] slope_y;
    wire [Y_W-1:0] coef_y;
    wire [Y_W-1:0] x_y;
    specfx_extend #(.IN_W(SLOPE_W), .IN_S(SLOPE_S), .OUT_W(Y_W)) u_slope_y (.x(slope_r), .y(slope_y));
    specfx_extend #(.IN_W(COEF_W), .IN_S(COEF_S), .OUT_W(Y_W)) u_coef_y (.x(coef_r), .y(coef_y));
    specfx_extend #(.IN_W(X_W), .IN_S(1), .OUT_W(Y_W)) u_x_y (.x(x), .y(x_y));
    wire [Y_W-1:0] operand = at_step[0] ? slope_y : at_step[K+1] ? coef_y : x_y;
    wire [P_W-1:0] product;
    specfx_mul #(.A_W(X_W), .A_S(1), .B_W(Y_W), .B_S(1), .P_W(P_W)) u_mul (
        .a(x), .b(operand), .p(product)
    );

    // ---- The quantizations of each step, all fed by the shared product. ----
    // Each takes the low bits that hold its own exact product (the width the matching
    // pipelined stage module computes).
    // results[s*X_W +: X_W] is step s's result as a signed X_W-bit value (s = 0..K).
    wire [(K+1)*X_W-1:0] results;

    // Step 0: t = Q_t(d * slope), then b = Q_b(cutoff(t + offset)).
    wire [T_W-1:0] t;
    wire [B_W-1:0] b;
    specfx_quant #(
        .IN_W(PT_W), .IN_F(D_F + SLOPE_F), .IN_S(1),
        .OUT_W(T_W), .OUT_F(T_F), .OUT_S(T_S), .RND(T_RND), .OVF(T_OVF)
    ) u_q_t (
        .x(product[PT_W-1:0]), .y(t)
    );
    specfx_add_b #(
        .T_W(T_W), .T_F(T_F), .T_S(T_S),
        .OFFSET_W(OFFSET_W), .OFFSET_F(OFFSET_F), .OFFSET_S(OFFSET_S),
        .C_W(C_W), .C_S(C_S), .CUTOFF(CUTOFF),
        .B_W(B_W), .B_F(B_F), .B_S(B_S), .B_RND(B_RND), .B_OVF(B_OVF)
    ) u_add_b (
        .t(t), .offset(offset_r), .c_clamped(c_cl_r), .threshold(threshold_r), .b(b)
    );
    specfx_extend #(.IN_W(B_W), .IN_S(B_S), .OUT_W(X_W)) u_b_x (.x(b), .y(results[0 +: X_W]));

    // Steps 1..K: sq_i = Q_i(x * x), x holding sq_{i-1}; Q_i(x) when i > depth_r.
    generate
        for (s = 1; s <= K; s = s + 1) begin : g_square
            wire [chain_w(s)-1:0] sq;
            localparam integer PS_W = 2 * chain_w(s - 1) + ((chain_s(s - 1) != 0) ? 0 : 1);
            localparam integer S_I = s;
            localparam [2:0] S_CODE = S_I[2:0];
            wire pass = (depth_r < S_CODE);
            specfx_sq_quant #(
                .P_W(PS_W), .X_W(X_W), .X_F(chain_f(s - 1)), .X_S(1),
                .Y_W(chain_w(s)), .Y_F(chain_f(s)), .Y_S(chain_s(s)),
                .Y_RND(sq_field(SQ_RND, s, 0)), .Y_OVF(sq_field(SQ_OVF, s, 0)),
                .BYPASS((s > DEPTH_MIN) ? 1 : 0)
            ) u_q_sq (
                .product(product[PS_W-1:0]), .x(x), .pass(pass), .y(sq)
            );
            specfx_extend #(.IN_W(chain_w(s)), .IN_S(chain_s(s)), .OUT_W(X_W)) u_sq_x (
                .x(sq), .y(results[s*X_W +: X_W])
            );
        end
    endgenerate

    // Step K + 1: out = Q_out(sq_K * coef).
    wire [OUT_W-1:0] out_q;
    specfx_quant #(
        .IN_W(PO_W), .IN_F(chain_f(K) + COEF_F), .IN_S(1),
        .OUT_W(OUT_W), .OUT_F(OUT_F), .OUT_S(OUT_S), .RND(OUT_RND), .OVF(OUT_OVF)
    ) u_q_out (
        .x(product[PO_W-1:0]), .y(out_q)
    );

    // The result of the running step (0..K), an AND-OR multiplexer.
    reg [X_W-1:0] step_result;
    integer j;
    always @* begin
        step_result = {X_W{1'b0}};
        for (j = 0; j <= K; j = j + 1)
            step_result = step_result | ({X_W{at_step[j]}} & results[j*X_W +: X_W]);
    end

    // depth_r goes nowhere when no step has a bypass (synthesis removes it).
    wire _unused_depth_ok = &{1'b0, depth_r};

    // ---- Control registers. ----
    always @(posedge clk) begin
        if (rst) begin
            busy      <= 1'b0;
            step      <= {STEP_W{1'b0}};
            count     <= {CNT_W{1'b0}};
            out_valid <= 1'b0;
        end else begin
            if (busy && !last) begin
                if (count_done) begin
                    count <= {CNT_W{1'b0}};
                    step  <= step + 1'b1;
                end else begin
                    count <= count + 1'b1;
                end
            end
            if (out_load) begin
                out_valid <= 1'b1;
                busy      <= 1'b0;
            end else if (out_valid && out_ready) begin
                out_valid <= 1'b0;
            end
            if (in_fire) begin
                busy  <= 1'b1;
                step  <= {STEP_W{1'b0}};
                count <= {CNT_W{1'b0}};
            end
        end
    end

    // ---- Data registers (reset only when RESET_DATA = 1). ----
    always @(posedge clk) begin
        if (RESET_DATA != 0 && rst) begin
            x           <= {X_W{1'b0}};
            out_data    <= {OUT_W{1'b0}};
            slope_r     <= {SLOPE_W{1'b0}};
            offset_r    <= {OFFSET_W{1'b0}};
            threshold_r <= {C_W{1'b0}};
            c_cl_r      <= {C_W{1'b0}};
            coef_r      <= {COEF_W{1'b0}};
            depth_r     <= 3'd0;
        end else begin
            if (step_done) x <= step_result;
            if (out_load) out_data <= out_q;
            if (in_fire) begin
                x           <= d_x;
                slope_r     <= in_slope;
                offset_r    <= in_offset;
                threshold_r <= in_threshold;
                c_cl_r      <= c_cl_in;
                coef_r      <= in_coef;
                depth_r     <= in_depth;
            end
        end
    end
endmodule

`default_nettype wire
