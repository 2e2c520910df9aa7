/* SPDX-License-Identifier: Apache-2.0 */
/* The register blocks every STM32 port of bristle shares, with the same
 * layout on the STM32H7 (RM0433) and the STM32G4 (RM0440): the TIMx block
 * from CR1 to BDTR (advanced and general-purpose timers alike; past BDTR the
 * families differ, and no port uses those registers), GPIO, the independent
 * watchdog and the Cortex-M SysTick (ARMv7-M). A part's own blocks (RCC, PWR,
 * flash) and its base addresses are in its port's br_<part>_regs.h.
 *
 * Each block is a struct of volatile 32-bit registers so that a port can be
 * pointed at the real peripheral address or, in host tests, at a plain struct
 * in RAM (a fake register block). Offsets are checked at compile time in
 * br_stm32.c. */
#ifndef BR_STM32_REGS_H
#define BR_STM32_REGS_H

#include <stdint.h>

#define BR_STM32_SYSTICK_BASE 0xE000E010u /* Cortex-M system timer */

/* A register block's layout checked at compile time against its reference
 * manual, in the driver file that uses the block (C99 has no static_assert:
 * a negative array size fails the build). */
#define BR_STM32_LAYOUT_CHECK(name, cond) typedef char br_stm32_layout_##name[(cond) ? 1 : -1]

/* ---- TIMx, CR1 .. BDTR ----------------------------------------------------- */
typedef struct {
    volatile uint32_t CR1;    /* 0x00 control 1 */
    volatile uint32_t CR2;    /* 0x04 control 2 */
    volatile uint32_t SMCR;   /* 0x08 slave mode control */
    volatile uint32_t DIER;   /* 0x0C DMA/interrupt enable */
    volatile uint32_t SR;     /* 0x10 status */
    volatile uint32_t EGR;    /* 0x14 event generation */
    volatile uint32_t CCMR1;  /* 0x18 capture/compare mode 1 */
    volatile uint32_t CCMR2;  /* 0x1C capture/compare mode 2 */
    volatile uint32_t CCER;   /* 0x20 capture/compare enable */
    volatile uint32_t CNT;    /* 0x24 counter (32 bits on TIM2/TIM5) */
    volatile uint32_t PSC;    /* 0x28 prescaler */
    volatile uint32_t ARR;    /* 0x2C auto-reload */
    volatile uint32_t RCR;    /* 0x30 repetition counter (advanced only) */
    volatile uint32_t CCR1;   /* 0x34 */
    volatile uint32_t CCR2;   /* 0x38 */
    volatile uint32_t CCR3;   /* 0x3C */
    volatile uint32_t CCR4;   /* 0x40 */
    volatile uint32_t BDTR;   /* 0x44 break and dead-time (advanced only) */
} br_stm32_tim_t;

/* CR1 */
#define BR_TIM_CR1_CEN         (1u << 0)
#define BR_TIM_CR1_UDIS        (1u << 1)
#define BR_TIM_CR1_DIR         (1u << 4)
#define BR_TIM_CR1_CMS_Pos     5u
#define BR_TIM_CR1_CMS_Msk     (3u << BR_TIM_CR1_CMS_Pos)
#define BR_TIM_CR1_CMS_CENTER1 (1u << BR_TIM_CR1_CMS_Pos) /* centre-aligned mode 1 */
#define BR_TIM_CR1_ARPE        (1u << 7)
/* SMCR: SMS[2:0] at bits 2:0, SMS[3] at bit 16 */
#define BR_TIM_SMCR_SMS_Msk    ((7u << 0) | (1u << 16))
#define BR_TIM_SMCR_SMS_ENC3   (3u << 0) /* encoder mode 3: count on TI1 and TI2 edges */
/* EGR */
#define BR_TIM_EGR_UG          (1u << 0)
/* CCMR1, input capture */
#define BR_TIM_CCMR1_CC1S_TI1  (1u << 0)  /* CC1 input, IC1 on TI1 */
#define BR_TIM_CCMR1_IC1F_Pos  4u
#define BR_TIM_CCMR1_CC2S_TI2  (1u << 8)  /* CC2 input, IC2 on TI2 */
#define BR_TIM_CCMR1_IC2F_Pos  12u
/* CCMR1, output compare */
#define BR_TIM_CCMR1_OC1PE     (1u << 3)
#define BR_TIM_CCMR1_OC1M_Pos  4u
#define BR_TIM_CCMR1_OC2PE     (1u << 11)
#define BR_TIM_CCMR1_OC2M_Pos  12u
#define BR_TIM_OCM_PWM1        6u          /* OCxREF high while CNT < CCRx */
/* CCER */
#define BR_TIM_CCER_CC1E       (1u << 0)
#define BR_TIM_CCER_CC1P       (1u << 1)
#define BR_TIM_CCER_CC1NE      (1u << 2)
#define BR_TIM_CCER_CC2E       (1u << 4)
#define BR_TIM_CCER_CC2P       (1u << 5)
#define BR_TIM_CCER_CC2NE      (1u << 6)
/* BDTR */
#define BR_TIM_BDTR_DTG_Msk    0xFFu
#define BR_TIM_BDTR_OSSI       (1u << 10)
#define BR_TIM_BDTR_OSSR       (1u << 11)
#define BR_TIM_BDTR_MOE        (1u << 15)

/* ---- IWDG (independent watchdog, LSI ~32 kHz) ----------------------------- */
typedef struct {
    volatile uint32_t KR;   /* 0x00 key */
    volatile uint32_t PR;   /* 0x04 prescaler: 0 = /4, 1 = /8, ... 6 = /256 */
    volatile uint32_t RLR;  /* 0x08 reload, 12 bits */
    volatile uint32_t SR;   /* 0x0C PVU, RVU, WVU: an update in progress */
    volatile uint32_t WINR; /* 0x10 window */
} br_stm32_iwdg_t;

#define BR_IWDG_KEY_START   0xCCCCu /* starts the watchdog (and the LSI) */
#define BR_IWDG_KEY_ACCESS  0x5555u /* unlocks PR, RLR, WINR */
#define BR_IWDG_KEY_REFRESH 0xAAAAu /* reloads the counter from RLR */
#define BR_IWDG_PR_MAX      6u      /* /256 */
#define BR_IWDG_RLR_MAX     0xFFFu

/* ---- GPIO ---------------------------------------------------------------- */
typedef struct {
    volatile uint32_t MODER;   /* 0x00 2 bits per pin: 00 in, 01 out, 10 AF, 11 analog */
    volatile uint32_t OTYPER;  /* 0x04 */
    volatile uint32_t OSPEEDR; /* 0x08 2 bits per pin */
    volatile uint32_t PUPDR;   /* 0x0C 2 bits per pin */
    volatile uint32_t IDR;     /* 0x10 */
    volatile uint32_t ODR;     /* 0x14 */
    volatile uint32_t BSRR;    /* 0x18 */
    volatile uint32_t LCKR;    /* 0x1C */
    volatile uint32_t AFR[2];  /* 0x20 AFRL (pins 0..7), 0x24 AFRH (8..15), 4 bits per pin */
} br_stm32_gpio_t;

#define BR_GPIO_MODE_AF   2u
#define BR_GPIO_SPEED_HI  2u

/* ---- SysTick (ARMv7-M) ---------------------------------------------------- */
typedef struct {
    volatile uint32_t CTRL;  /* 0x00 control and status */
    volatile uint32_t LOAD;  /* 0x04 reload value, 24 bits */
    volatile uint32_t VAL;   /* 0x08 current value; any write clears it and COUNTFLAG */
    volatile uint32_t CALIB; /* 0x0C */
} br_stm32_systick_t;

#define BR_SYSTICK_CTRL_ENABLE    (1u << 0)
#define BR_SYSTICK_CTRL_TICKINT   (1u << 1)
#define BR_SYSTICK_CTRL_CLKSOURCE (1u << 2)  /* 1: processor clock */
#define BR_SYSTICK_CTRL_COUNTFLAG (1u << 16) /* set on reload, cleared by reading CTRL */
#define BR_SYSTICK_LOAD_MAX       0x00FFFFFFu

/* ---- USART (RM0433 / RM0440: the same block on both, with the FIFO) ----- */
typedef struct {
    volatile uint32_t CR1;   /* 0x00 UE, RE, TE, FIFOEN */
    volatile uint32_t CR2;   /* 0x04 stop bits (00: 1) */
    volatile uint32_t CR3;   /* 0x08 DMAR, DMAT, OVRDIS */
    volatile uint32_t BRR;   /* 0x0C baud rate: kernel clock / baud (oversampling 16) */
    volatile uint32_t GTPR;  /* 0x10 */
    volatile uint32_t RTOR;  /* 0x14 */
    volatile uint32_t RQR;   /* 0x18 */
    volatile uint32_t ISR;   /* 0x1C PE, FE, NE, ORE, ..., TC, TXE */
    volatile uint32_t ICR;   /* 0x20 the ISR flags' clear bits */
    volatile uint32_t RDR;   /* 0x24 received byte (the RX DMA's source) */
    volatile uint32_t TDR;   /* 0x28 byte to send (the TX DMA's destination) */
    volatile uint32_t PRESC; /* 0x2C kernel clock prescaler (0: /1) */
} br_stm32_usart_t;

#define BR_USART_CR1_UE      (1u << 0)
#define BR_USART_CR1_RE      (1u << 2)
#define BR_USART_CR1_TE      (1u << 3)
#define BR_USART_CR3_DMAR    (1u << 6)
#define BR_USART_CR3_DMAT    (1u << 7)
#define BR_USART_ISR_FE      (1u << 1)
#define BR_USART_ISR_NE      (1u << 2)
#define BR_USART_ISR_ORE     (1u << 3)
#define BR_USART_ICR_FECF    (1u << 1)
#define BR_USART_ICR_NECF    (1u << 2)
#define BR_USART_ICR_ORECF   (1u << 3)
#define BR_USART_BRR_MIN     16u      /* oversampling 16: BRR >= 16 */
#define BR_USART_BRR_MAX     0xFFFFu

/* ---- DMA: one stream (H7) or channel (G4), its first four registers ------ */
/* The H7's DMA1/DMA2 stream (SxCR, SxNDTR, SxPAR, SxM0AR, then M1AR, FCR) and
 * the G4's DMA channel (CCRx, CNDTRx, CPARx, CMARx) begin with the same four
 * registers at the same offsets, with EN at bit 0 of the first. Their other
 * bits differ (direction, circular, increment): the part's port gives the
 * configuration words (bristle/br_stm32_usart.h), and its register map holds
 * the whole block. */
typedef struct {
    volatile uint32_t CR;   /* 0x00 configuration; EN bit 0 */
    volatile uint32_t NDTR; /* 0x04 items left to transfer (circular: reloaded at 0) */
    volatile uint32_t PAR;  /* 0x08 peripheral address */
    volatile uint32_t MAR;  /* 0x0C memory address (the H7's M0AR) */
} br_stm32_dma_ch_t;

#define BR_DMA_CR_EN        (1u << 0)
#define BR_DMA_NDTR_MAX     0xFFFFu

#endif
