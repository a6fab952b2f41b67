-- Language: VHDL-2008

-- gyrofx_gyro_loop — one vibratory gyro's digital loop: drive PLL and AGC, sense
-- demodulation, CIC decimation and the mode switch of mode reversal.
--
-- Purpose: the VHDL twin of gyrofx_gyro_loop.v (same generics, ports and timing): closes
--   the drive loop around the resonator (ADC codes of both axes in, DAC codes out) and
--   turns the sense axis into the chain's rate in deg/s (SPEC 1.6). Bit-exact with
--   gyrofx_model::gyro_loop::FixedGyroLoop; docs/blocks/gyro_loop.md documents it.
--
-- Algorithm (per ADC sample, ce high; mode '1' normal: drive x, sense y; '0' reverse:
--   drive y, sense x; _N / _R generics are the two modes' values):
--     on a change of mode (and at the first sample after reset), before the sample:
--     PLL integrator <= PLL_PRESET, NCO word <= FREQ_WORD, AGC integrator, both
--     demodulators, the lock filters and counter and the DAC delay line cleared
--     (sin_D, cos_D) = NCO(freq, 0), cos_T = NCO(freq, DAC_OFFSET),
--     (sin_S, cos_S) = NCO(freq, SENSE_OFFSET)
--     (I_D, Q_D) = demod(adc_drive), (I_S, Q_S) = demod(adc_sense)
--     freq <= PLL(Q_D); e_A = Q(SETPOINT - I_D); dac = Q(AGC(e_A) * cos_T), output
--     LATENCY samples later; lock filters z <= z - (z >> LOCK_SHIFT) + e on Q_D and e_A;
--     locked after LOCK_HOLD samples with both |z| < LOCK_*; every DECIMATION-th sample
--     rate = Q(RATE_COEF * CIC(I_S)), quadrature = Q(QUAD_COEF * CIC(Q_S)), out_valid
--
-- Pipeline: four register stages; the outputs are valid 4 clocks after ce, and ce must
--   come at most every 4th clock. A clock with rst high clears every register.

library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;

entity gyrofx_gyro_loop is
    generic (
        -- NCOs: phase bits, quarter-wave ROM address bits, sine width, truncation error feedback
        NCO_PHASE_W : positive := 32;
        NCO_ADDR_W : positive := 10;
        NCO_SIN_W : positive := 18;
        NCO_ERROR_FEEDBACK : natural := 1;
        -- demodulators (both)
        DEMOD_ADC_W : positive := 24;
        DEMOD_ADC_F : integer := 23;
        DEMOD_REF_W : positive := 18;
        DEMOD_REF_F : integer := 17;
        DEMOD_PROD_W : positive := 36;
        DEMOD_PROD_F : integer := 34;
        DEMOD_STATE_W : positive := 44;
        DEMOD_STATE_F : integer := 42;
        DEMOD_OUT_W : positive := 32;
        DEMOD_OUT_F : integer := 30;
        DEMOD_SHIFT : positive := 8;
        -- PLL: error, gains, integrator, output (the NCO word)
        PLL_ERR_W : positive := 32;
        PLL_ERR_F : integer := 30;
        PLL_KP_W : positive := 18;
        PLL_KP_F : integer := 27;
        PLL_KI_W : positive := 18;
        PLL_KI_F : integer := 38;
        PLL_INT_W : positive := 40;
        PLL_INT_F : integer := 38;
        PLL_OUT_W : positive := 32;
        PLL_OUT_F : integer := 32;
        PLL_KP : std_logic_vector := 18x"10625";
        PLL_KI : std_logic_vector := 18x"17795";
        PLL_INT_MIN : std_logic_vector := 40x"292cd0c7b";
        PLL_INT_MAX : std_logic_vector := 40x"2a786ac8d";
        -- AGC: error, gains, integrator, output (DAC LSB)
        AGC_ERR_W : positive := 32;
        AGC_ERR_F : integer := 30;
        AGC_KP_W : positive := 18;
        AGC_KP_F : integer := 1;
        AGC_KI_W : positive := 18;
        AGC_KI_F : integer := 11;
        AGC_INT_W : positive := 40;
        AGC_INT_F : integer := 20;
        AGC_OUT_W : positive := 24;
        AGC_OUT_F : integer := 6;
        AGC_KP : std_logic_vector := 18x"19a9a";
        AGC_KI : std_logic_vector := 18x"12624";
        AGC_INT_MIN : std_logic_vector := 40x"0";
        AGC_INT_MAX : std_logic_vector := 40x"1ffff00000";
        -- CICs (both)
        CIC_IN_W : positive := 32;
        CIC_IN_F : integer := 30;
        CIC_STAGES : positive := 3;
        CIC_DECIMATION : positive := 1000;
        CIC_DELAY : positive := 1;
        CIC_SHIFT : natural := 30;
        CIC_MID_W : positive := 40;
        CIC_MID_F : integer := 38;
        CIC_TAPS : positive := 5;
        CIC_COEF_W : positive := 18;
        CIC_COEF_F : integer := 16;
        CIC_OUT_W : positive := 32;
        CIC_OUT_F : integer := 30;
        -- DAC codes, rate/quadrature output (deg/s), the 1/SF coefficients' format
        DAC_W : positive := 18;
        DAC_F : integer := 0;
        OUT_W : positive := 24;
        OUT_F : integer := 14;
        COEF_W : positive := 24;
        COEF_F : integer := 6;
        -- ADC-to-DAC latency, samples (0..8)
        LATENCY : natural := 1;
        -- lock detector
        LOCK_SHIFT : positive := 9;
        LOCK_HOLD : natural := 2000;
        -- per mode (_N normal, _R reverse)
        SETPOINT_N : std_logic_vector := 32x"cccc666";
        SETPOINT_R : std_logic_vector := 32x"cccc666";
        FREQ_WORD_N : std_logic_vector := 32x"a7d5617";
        FREQ_WORD_R : std_logic_vector := 32x"a6bf8ce";
        PLL_PRESET_N : std_logic_vector := 40x"29f5585a4";
        PLL_PRESET_R : std_logic_vector := 40x"29afe3365";
        DAC_OFFSET_N : std_logic_vector := 32x"fd38ab7";
        DAC_OFFSET_R : std_logic_vector := 32x"fbb6e38";
        SENSE_OFFSET_N : std_logic_vector := 32x"4f56436e";
        SENSE_OFFSET_R : std_logic_vector := 32x"afd6e2bb";
        RATE_COEF_N : std_logic_vector := 24x"63db80";
        RATE_COEF_R : std_logic_vector := 24x"9aa98a";
        QUAD_COEF_N : std_logic_vector := 24x"9c2480";
        QUAD_COEF_R : std_logic_vector := 24x"9aa98a";
        LOCK_Q_N : std_logic_vector := 64x"b70271b";
        LOCK_Q_R : std_logic_vector := 64x"b70271b";
        LOCK_A_N : std_logic_vector := 64x"68db574";
        LOCK_A_R : std_logic_vector := 64x"68db574";
        -- rounding: 0 floor, 1 ceil, 2 zero, 3 nearest, 4 round, 5 convergent
        ROUNDING : natural := 3;
        -- overflow: 0 wrap, 1 saturate
        SATURATE : natural := 1;
        -- ROM images
        NCO_ROM_FILE : string := "nco_sine.mem";
        CIC_ROM_FILE : string := "cic_taps.mem"
    );
    port (
        clk        : in  std_logic;
        rst        : in  std_logic;
        ce         : in  std_logic;
        mode       : in  std_logic;
        adc_x      : in  signed(DEMOD_ADC_W - 1 downto 0);
        adc_y      : in  signed(DEMOD_ADC_W - 1 downto 0);
        dac_x      : out signed(DAC_W - 1 downto 0);
        dac_y      : out signed(DAC_W - 1 downto 0);
        rate       : out signed(OUT_W - 1 downto 0);
        quadrature : out signed(OUT_W - 1 downto 0);
        out_valid  : out std_logic;
        locked     : out std_logic
    );
end entity;

architecture rtl of gyrofx_gyro_loop is

    -- `bits` as a code of `width` bits; another length stops the elaboration.
    function code_of(name : string; bits : std_logic_vector; width : positive)
        return std_logic_vector is
        variable result : std_logic_vector(width - 1 downto 0) := (others => '0');
    begin
        assert bits'length = width
            report "gyrofx_gyro_loop: " & name & " has " & integer'image(bits'length)
                & " bits; " & integer'image(width) & " are needed"
            severity failure;
        if bits'length = width then
            result := bits;
        end if;
        return result;
    end function;

    constant Z_W : positive := DEMOD_OUT_W + LOCK_SHIFT + 1;
    constant DRIVE_W : positive := AGC_OUT_W + NCO_SIN_W;
    constant DRIVE_F : integer := AGC_OUT_F + NCO_SIN_W - 1;
    constant RATE_W : positive := CIC_OUT_W + COEF_W;
    constant RATE_F : integer := CIC_OUT_F + COEF_F;
    constant DELAY_N : positive := maximum(LATENCY, 1);

    constant SETPOINT_N_C : signed(DEMOD_OUT_W - 1 downto 0) :=
        signed(code_of("SETPOINT_N", SETPOINT_N, DEMOD_OUT_W));
    constant SETPOINT_R_C : signed(DEMOD_OUT_W - 1 downto 0) :=
        signed(code_of("SETPOINT_R", SETPOINT_R, DEMOD_OUT_W));
    constant FREQ_WORD_N_C : unsigned(NCO_PHASE_W - 1 downto 0) :=
        unsigned(code_of("FREQ_WORD_N", FREQ_WORD_N, NCO_PHASE_W));
    constant FREQ_WORD_R_C : unsigned(NCO_PHASE_W - 1 downto 0) :=
        unsigned(code_of("FREQ_WORD_R", FREQ_WORD_R, NCO_PHASE_W));
    constant PLL_PRESET_N_C : signed(PLL_INT_W - 1 downto 0) :=
        signed(code_of("PLL_PRESET_N", PLL_PRESET_N, PLL_INT_W));
    constant PLL_PRESET_R_C : signed(PLL_INT_W - 1 downto 0) :=
        signed(code_of("PLL_PRESET_R", PLL_PRESET_R, PLL_INT_W));
    constant DAC_OFFSET_N_C : unsigned(NCO_PHASE_W - 1 downto 0) :=
        unsigned(code_of("DAC_OFFSET_N", DAC_OFFSET_N, NCO_PHASE_W));
    constant DAC_OFFSET_R_C : unsigned(NCO_PHASE_W - 1 downto 0) :=
        unsigned(code_of("DAC_OFFSET_R", DAC_OFFSET_R, NCO_PHASE_W));
    constant SENSE_OFFSET_N_C : unsigned(NCO_PHASE_W - 1 downto 0) :=
        unsigned(code_of("SENSE_OFFSET_N", SENSE_OFFSET_N, NCO_PHASE_W));
    constant SENSE_OFFSET_R_C : unsigned(NCO_PHASE_W - 1 downto 0) :=
        unsigned(code_of("SENSE_OFFSET_R", SENSE_OFFSET_R, NCO_PHASE_W));
    constant RATE_COEF_N_C : signed(COEF_W - 1 downto 0) :=
        signed(code_of("RATE_COEF_N", RATE_COEF_N, COEF_W));
    constant RATE_COEF_R_C : signed(COEF_W - 1 downto 0) :=
        signed(code_of("RATE_COEF_R", RATE_COEF_R, COEF_W));
    constant QUAD_COEF_N_C : signed(COEF_W - 1 downto 0) :=
        signed(code_of("QUAD_COEF_N", QUAD_COEF_N, COEF_W));
    constant QUAD_COEF_R_C : signed(COEF_W - 1 downto 0) :=
        signed(code_of("QUAD_COEF_R", QUAD_COEF_R, COEF_W));
    constant LOCK_Q_N_C : signed(63 downto 0) := signed(code_of("LOCK_Q_N", LOCK_Q_N, 64));
    constant LOCK_Q_R_C : signed(63 downto 0) := signed(code_of("LOCK_Q_R", LOCK_Q_R, 64));
    constant LOCK_A_N_C : signed(63 downto 0) := signed(code_of("LOCK_A_N", LOCK_A_N, 64));
    constant LOCK_A_R_C : signed(63 downto 0) := signed(code_of("LOCK_A_R", LOCK_A_R, 64));

    type delay_array is array (0 to DELAY_N - 1) of signed(DAC_W - 1 downto 0);

    -- stage 0
    signal mode_reg : std_logic := '1';
    signal start_reg : std_logic := '1';
    signal ce_1_reg : std_logic := '0';
    signal ce_2_reg : std_logic := '0';
    signal ce_3_reg : std_logic := '0';
    signal freq_reg : unsigned(NCO_PHASE_W - 1 downto 0) := (others => '0');
    signal adc_x_reg : signed(DEMOD_ADC_W - 1 downto 0) := (others => '0');
    signal adc_y_reg : signed(DEMOD_ADC_W - 1 downto 0) := (others => '0');
    signal switching : std_logic;
    signal demod_rst : std_logic;
    signal freq_now : unsigned(NCO_PHASE_W - 1 downto 0);
    signal dac_offset : unsigned(NCO_PHASE_W - 1 downto 0);
    signal sense_offset : unsigned(NCO_PHASE_W - 1 downto 0);
    signal drive_sin : signed(NCO_SIN_W - 1 downto 0);
    signal drive_cos : signed(NCO_SIN_W - 1 downto 0);
    signal transmit_cos : signed(NCO_SIN_W - 1 downto 0);
    signal sense_sin : signed(NCO_SIN_W - 1 downto 0);
    signal sense_cos : signed(NCO_SIN_W - 1 downto 0);
    -- stage 1
    signal adc_drive : signed(DEMOD_ADC_W - 1 downto 0);
    signal adc_sense : signed(DEMOD_ADC_W - 1 downto 0);
    signal i_drive : signed(DEMOD_OUT_W - 1 downto 0);
    signal q_drive : signed(DEMOD_OUT_W - 1 downto 0);
    signal i_sense : signed(DEMOD_OUT_W - 1 downto 0);
    signal q_sense : signed(DEMOD_OUT_W - 1 downto 0);
    -- stage 2
    signal setpoint : signed(DEMOD_OUT_W - 1 downto 0);
    signal error_exact : signed(DEMOD_OUT_W downto 0);
    signal agc_error : signed(DEMOD_OUT_W - 1 downto 0);
    signal pll_preset_value : signed(PLL_INT_W - 1 downto 0);
    signal pll_out : signed(PLL_OUT_W - 1 downto 0);
    signal amplitude : signed(AGC_OUT_W - 1 downto 0);
    signal cic_i : signed(CIC_OUT_W - 1 downto 0);
    signal cic_q : signed(CIC_OUT_W - 1 downto 0);
    signal cic_valid : std_logic;
    -- stage 3
    signal drive_exact : signed(DRIVE_W - 1 downto 0);
    signal drive : signed(DAC_W - 1 downto 0);
    signal delay_reg : delay_array := (others => (others => '0'));
    signal dac_now : signed(DAC_W - 1 downto 0);
    signal z_q_reg : signed(Z_W - 1 downto 0) := (others => '0');
    signal z_a_reg : signed(Z_W - 1 downto 0) := (others => '0');
    signal z_q_next : signed(Z_W - 1 downto 0);
    signal z_a_next : signed(Z_W - 1 downto 0);
    signal lock_count_reg : unsigned(31 downto 0) := (others => '0');
    signal lock_count_next : unsigned(31 downto 0);
    signal lock_q : signed(63 downto 0);
    signal lock_a : signed(63 downto 0);
    signal within_limits : boolean;
    signal rate_coef : signed(COEF_W - 1 downto 0);
    signal quad_coef : signed(COEF_W - 1 downto 0);
    signal rate_exact : signed(RATE_W - 1 downto 0);
    signal quad_exact : signed(RATE_W - 1 downto 0);
    signal rate_next : signed(OUT_W - 1 downto 0);
    signal quad_next : signed(OUT_W - 1 downto 0);
    signal dac_x_reg : signed(DAC_W - 1 downto 0) := (others => '0');
    signal dac_y_reg : signed(DAC_W - 1 downto 0) := (others => '0');
    signal rate_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal quad_reg : signed(OUT_W - 1 downto 0) := (others => '0');
    signal out_valid_reg : std_logic := '0';
    signal locked_reg : std_logic := '0';

begin

    -- ---- stage 0: mode, switch actions, NCOs ----
    -- The enter actions of a mode change apply before this sample.
    switching <= '1' when ce = '1' and (mode /= mode_reg or start_reg = '1') else '0';
    demod_rst <= rst or switching;
    freq_now <= FREQ_WORD_N_C when switching = '1' and mode = '1' else
                FREQ_WORD_R_C when switching = '1' else
                freq_reg;
    dac_offset <= DAC_OFFSET_N_C when mode = '1' else DAC_OFFSET_R_C;
    sense_offset <= SENSE_OFFSET_N_C when mode = '1' else SENSE_OFFSET_R_C;

    nco_drive : entity work.gyrofx_nco
        generic map (
            PHASE_W => NCO_PHASE_W, ADDR_W => NCO_ADDR_W, SIN_W => NCO_SIN_W,
            ERROR_FEEDBACK => NCO_ERROR_FEEDBACK, ROM_FILE => NCO_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce, freq => freq_now, offset => (others => '0'),
            sin_out => drive_sin, cos_out => drive_cos, out_valid => open
        );

    nco_transmit : entity work.gyrofx_nco
        generic map (
            PHASE_W => NCO_PHASE_W, ADDR_W => NCO_ADDR_W, SIN_W => NCO_SIN_W,
            ERROR_FEEDBACK => NCO_ERROR_FEEDBACK, ROM_FILE => NCO_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce, freq => freq_now, offset => dac_offset,
            sin_out => open, cos_out => transmit_cos, out_valid => open
        );

    nco_sense : entity work.gyrofx_nco
        generic map (
            PHASE_W => NCO_PHASE_W, ADDR_W => NCO_ADDR_W, SIN_W => NCO_SIN_W,
            ERROR_FEEDBACK => NCO_ERROR_FEEDBACK, ROM_FILE => NCO_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce, freq => freq_now, offset => sense_offset,
            sin_out => sense_sin, cos_out => sense_cos, out_valid => open
        );

    -- ---- stage 1: demodulators ----
    adc_drive <= adc_x_reg when mode_reg = '1' else adc_y_reg;
    adc_sense <= adc_y_reg when mode_reg = '1' else adc_x_reg;

    demodulator_drive : entity work.gyrofx_demodulator
        generic map (
            ADC_W => DEMOD_ADC_W, ADC_F => DEMOD_ADC_F, REF_W => DEMOD_REF_W,
            REF_F => DEMOD_REF_F, PROD_W => DEMOD_PROD_W, PROD_F => DEMOD_PROD_F,
            STATE_W => DEMOD_STATE_W, STATE_F => DEMOD_STATE_F, OUT_W => DEMOD_OUT_W,
            OUT_F => DEMOD_OUT_F, SHIFT => DEMOD_SHIFT, ROUNDING => ROUNDING,
            SATURATE => SATURATE
        )
        port map (
            clk => clk, rst => demod_rst, ce => ce_1_reg, adc => adc_drive,
            ref_sin => drive_sin, ref_cos => drive_cos, i_out => i_drive, q_out => q_drive,
            out_valid => open
        );

    demodulator_sense : entity work.gyrofx_demodulator
        generic map (
            ADC_W => DEMOD_ADC_W, ADC_F => DEMOD_ADC_F, REF_W => DEMOD_REF_W,
            REF_F => DEMOD_REF_F, PROD_W => DEMOD_PROD_W, PROD_F => DEMOD_PROD_F,
            STATE_W => DEMOD_STATE_W, STATE_F => DEMOD_STATE_F, OUT_W => DEMOD_OUT_W,
            OUT_F => DEMOD_OUT_F, SHIFT => DEMOD_SHIFT, ROUNDING => ROUNDING,
            SATURATE => SATURATE
        )
        port map (
            clk => clk, rst => demod_rst, ce => ce_1_reg, adc => adc_sense,
            ref_sin => sense_sin, ref_cos => sense_cos, i_out => i_sense, q_out => q_sense,
            out_valid => open
        );

    -- ---- stage 2: PLL, AGC, CICs ----
    setpoint <= SETPOINT_N_C when mode_reg = '1' else SETPOINT_R_C;
    error_exact <= resize(setpoint, DEMOD_OUT_W + 1) - resize(i_drive, DEMOD_OUT_W + 1);

    quantize_agc_error : entity work.gyrofx_quantize
        generic map (
            IN_W => DEMOD_OUT_W + 1, IN_F => DEMOD_OUT_F, OUT_W => DEMOD_OUT_W,
            OUT_F => DEMOD_OUT_F, ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => error_exact, value_out => agc_error, overflow => open);

    pll_preset_value <= PLL_PRESET_N_C when mode = '1' else PLL_PRESET_R_C;

    pll : entity work.gyrofx_pi
        generic map (
            ERR_W => PLL_ERR_W, ERR_F => PLL_ERR_F, KP_W => PLL_KP_W, KP_F => PLL_KP_F,
            KI_W => PLL_KI_W, KI_F => PLL_KI_F, INT_W => PLL_INT_W, INT_F => PLL_INT_F,
            OUT_W => PLL_OUT_W, OUT_F => PLL_OUT_F, KP => PLL_KP, KI => PLL_KI,
            INT_MIN => PLL_INT_MIN, INT_MAX => PLL_INT_MAX, ROUNDING => ROUNDING,
            SATURATE => SATURATE
        )
        port map (
            clk => clk, rst => rst, ce => ce_2_reg, err => q_drive, preset => switching,
            preset_value => pll_preset_value, u_out => pll_out, out_valid => open
        );

    agc : entity work.gyrofx_pi
        generic map (
            ERR_W => AGC_ERR_W, ERR_F => AGC_ERR_F, KP_W => AGC_KP_W, KP_F => AGC_KP_F,
            KI_W => AGC_KI_W, KI_F => AGC_KI_F, INT_W => AGC_INT_W, INT_F => AGC_INT_F,
            OUT_W => AGC_OUT_W, OUT_F => AGC_OUT_F, KP => AGC_KP, KI => AGC_KI,
            INT_MIN => AGC_INT_MIN, INT_MAX => AGC_INT_MAX, ROUNDING => ROUNDING,
            SATURATE => SATURATE
        )
        port map (
            clk => clk, rst => demod_rst, ce => ce_2_reg, err => agc_error, preset => '0',
            preset_value => (others => '0'), u_out => amplitude, out_valid => open
        );

    cic_in_phase : entity work.gyrofx_cic
        generic map (
            IN_W => CIC_IN_W, IN_F => CIC_IN_F, STAGES => CIC_STAGES,
            DECIMATION => CIC_DECIMATION, DELAY => CIC_DELAY, SHIFT => CIC_SHIFT,
            MID_W => CIC_MID_W, MID_F => CIC_MID_F, TAPS => CIC_TAPS, COEF_W => CIC_COEF_W,
            COEF_F => CIC_COEF_F, OUT_W => CIC_OUT_W, OUT_F => CIC_OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE, ROM_FILE => CIC_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce_2_reg, x => i_sense, y => cic_i,
            y_valid => cic_valid
        );

    cic_quadrature : entity work.gyrofx_cic
        generic map (
            IN_W => CIC_IN_W, IN_F => CIC_IN_F, STAGES => CIC_STAGES,
            DECIMATION => CIC_DECIMATION, DELAY => CIC_DELAY, SHIFT => CIC_SHIFT,
            MID_W => CIC_MID_W, MID_F => CIC_MID_F, TAPS => CIC_TAPS, COEF_W => CIC_COEF_W,
            COEF_F => CIC_COEF_F, OUT_W => CIC_OUT_W, OUT_F => CIC_OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE, ROM_FILE => CIC_ROM_FILE
        )
        port map (
            clk => clk, rst => rst, ce => ce_2_reg, x => q_sense, y => cic_q,
            y_valid => open
        );

    -- ---- stage 3: NCO word, DAC and its delay line, lock detector, outputs ----
    drive_exact <= amplitude * transmit_cos;

    quantize_dac : entity work.gyrofx_quantize
        generic map (
            IN_W => DRIVE_W, IN_F => DRIVE_F, OUT_W => DAC_W, OUT_F => DAC_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => drive_exact, value_out => drive, overflow => open);

    -- The DAC code of sample k is output at sample k + LATENCY; delay_reg(j) holds sample
    -- k-1-j's.
    dac_now <= drive when LATENCY = 0 else delay_reg(DELAY_N - 1);

    -- Lock filters: z <= z - floor(z / 2^LOCK_SHIFT) + e, exact in Z_W bits.
    z_q_next <= z_q_reg - shift_right(z_q_reg, LOCK_SHIFT) + resize(q_drive, Z_W);
    z_a_next <= z_a_reg - shift_right(z_a_reg, LOCK_SHIFT) + resize(agc_error, Z_W);
    lock_q <= LOCK_Q_N_C when mode_reg = '1' else LOCK_Q_R_C;
    lock_a <= LOCK_A_N_C when mode_reg = '1' else LOCK_A_R_C;
    -- |z| < limit in 66 bits: wide enough for |z| (Z_W <= 64) and the 64-bit limits.
    within_limits <= abs(resize(z_q_next, 66)) < resize(lock_q, 66)
                     and abs(resize(z_a_next, 66)) < resize(lock_a, 66);
    lock_count_next <= (others => '0') when not within_limits else
                       to_unsigned(LOCK_HOLD, 32) when lock_count_reg >= LOCK_HOLD else
                       lock_count_reg + 1;

    -- Rate and quadrature, deg/s.
    rate_coef <= RATE_COEF_N_C when mode_reg = '1' else RATE_COEF_R_C;
    quad_coef <= QUAD_COEF_N_C when mode_reg = '1' else QUAD_COEF_R_C;
    rate_exact <= rate_coef * cic_i;
    quad_exact <= quad_coef * cic_q;

    quantize_rate : entity work.gyrofx_quantize
        generic map (
            IN_W => RATE_W, IN_F => RATE_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => rate_exact, value_out => rate_next, overflow => open);

    quantize_quadrature : entity work.gyrofx_quantize
        generic map (
            IN_W => RATE_W, IN_F => RATE_F, OUT_W => OUT_W, OUT_F => OUT_F,
            ROUNDING => ROUNDING, SATURATE => SATURATE
        )
        port map (value_in => quad_exact, value_out => quad_next, overflow => open);

    registers : process (clk)
    begin
        if rising_edge(clk) then
            ce_1_reg <= ce;
            ce_2_reg <= ce_1_reg;
            ce_3_reg <= ce_2_reg;
            out_valid_reg <= '0';

            if ce = '1' then
                mode_reg <= mode;
                start_reg <= '0';
                adc_x_reg <= adc_x;
                adc_y_reg <= adc_y;
            end if;
            if switching = '1' then
                z_q_reg <= (others => '0');
                z_a_reg <= (others => '0');
                lock_count_reg <= (others => '0');
                delay_reg <= (others => (others => '0'));
            end if;

            if ce_3_reg = '1' then
                freq_reg <= unsigned(pll_out(NCO_PHASE_W - 1 downto 0));
                if mode_reg = '1' then
                    dac_x_reg <= dac_now;
                    dac_y_reg <= (others => '0');
                else
                    dac_x_reg <= (others => '0');
                    dac_y_reg <= dac_now;
                end if;
                delay_reg(0) <= drive;
                for j in 1 to DELAY_N - 1 loop
                    delay_reg(j) <= delay_reg(j - 1);
                end loop;
                z_q_reg <= z_q_next;
                z_a_reg <= z_a_next;
                lock_count_reg <= lock_count_next;
                if lock_count_next >= LOCK_HOLD then
                    locked_reg <= '1';
                else
                    locked_reg <= '0';
                end if;
                if cic_valid = '1' then
                    rate_reg <= rate_next;
                    quad_reg <= quad_next;
                    out_valid_reg <= '1';
                end if;
            end if;

            if rst = '1' then
                mode_reg <= '1';
                start_reg <= '1';
                ce_1_reg <= '0';
                ce_2_reg <= '0';
                ce_3_reg <= '0';
                freq_reg <= (others => '0');
                adc_x_reg <= (others => '0');
                adc_y_reg <= (others => '0');
                z_q_reg <= (others => '0');
                z_a_reg <= (others => '0');
                lock_count_reg <= (others => '0');
                delay_reg <= (others => (others => '0'));
                dac_x_reg <= (others => '0');
                dac_y_reg <= (others => '0');
                rate_reg <= (others => '0');
                quad_reg <= (others => '0');
                out_valid_reg <= '0';
                locked_reg <= '0';
            end if;
        end if;
    end process;

    dac_x <= dac_x_reg;
    dac_y <= dac_y_reg;
    rate <= rate_reg;
    quadrature <= quad_reg;
    out_valid <= out_valid_reg;
    locked <= locked_reg;

    -- pragma translate_off
    -- Simulation only: the loop takes a sample at most every 4 clocks (gyrofx_job::pipeline);
    -- a sooner ce stops the simulation, naming this instance.
    spacing_check : entity work.gyrofx_spacing_check
        generic map (MIN_CLOCKS_PER_SAMPLE => 4, BLOCK_NAME => "gyrofx_gyro_loop")
        port map (clk => clk, rst => rst, ce => ce);
    -- pragma translate_on
end architecture;
